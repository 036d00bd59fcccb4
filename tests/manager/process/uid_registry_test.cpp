// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry with real sim_manager processes on loopback (no balancer: the test follows the redirects
// itself): a uid's first host keeps it, the others send its participant there, concurrent starts on every
// host make one session, a killed or restarted home keeps its uids, two hosts down means "try again" with
// nothing created, two hosts down in turn lock nothing out, a split left by earlier ballots is finished, a full
// or drained host sends a uid that lives elsewhere to its home but claims no new one, and the registry port
// refuses forged, stale, misaddressed and foreign-list lines.
#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sqlite3.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <fstream>
#include <map>
#include <memory>
#include <thread>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::admin_post;
using rfbsim::test::free_loopback_port;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
namespace net = rfbsim::test::net;

namespace {

const std::string kSecret = "registry-test-secret-0123456789";

// Lower-case hex HMAC-SHA256, written here again so that the test does not trust the manager's own.
std::string hmac_hex(const std::string& secret, const std::string& text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  HMAC(EVP_sha256(), secret.data(), static_cast<int>(secret.size()),
       reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest, &length);
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) {
    static const char* const kHex = "0123456789abcdef";
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0xf];
  }
  return hex;
}

// The registry's message key for these peers ("id=address:port" lines, sorted), derived here again.
std::string registry_key(const std::string& secret, std::vector<std::string> peer_lines) {
  std::sort(peer_lines.begin(), peer_lines.end());
  std::string text = "rfbsim-registry-v2\n";
  for (const std::string& line : peer_lines) text += line + "\n";
  return hmac_hex(secret, text);
}

// `text` and its hmac under `key`, as one line.
std::string signed_line(const std::string& key, const std::string& text) {
  return text + " " + hmac_hex(key, text) + "\n";
}

long long unix_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Sends `text` to 127.0.0.1:`port` and returns everything read until the peer closes (or 5 s pass).
std::string ask_registry(int port, const std::string& text) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  std::string answer;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
      ::send(fd, text.data(), text.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(text.size())) {
    char buffer[512];
    ssize_t got = 0;
    while ((got = ::recv(fd, buffer, sizeof buffer, 0)) > 0) answer.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(fd);
  return answer;
}

// Hosts h1..hN with their registries on fixed loopback ports, each in a data folder of its own.
class Cluster {
 public:
  // `max_sessions`: each host's slots (1 makes a host with one live session full).
  explicit Cluster(int hosts = 3, int max_sessions = 8) : count_(hosts), max_sessions_(max_sessions) {
    secret_file_ = (secret_dir_.path() / "cluster.secret").string();
    std::ofstream(secret_file_) << kSecret << "\n";
    ::chmod(secret_file_.c_str(), 0600);
    std::string peers;
    for (int i = 0; i < count_; ++i) {
      registry_ports_.push_back(free_loopback_port());
      peer_lines_.push_back(id(i) + "=127.0.0.1:" + std::to_string(registry_ports_.back()));
      peers += (i == 0 ? "" : ",") + peer_lines_.back();
    }
    peers_ = peers;
    for (int i = 0; i < count_; ++i) {
      data_.push_back(std::make_unique<TempDir>("rfbsim-registry-test"));
      hosts_.emplace_back();
      start(i);
    }
  }

  [[nodiscard]] int size() const { return count_; }
  // The message key every host of this cluster signs with.
  [[nodiscard]] std::string key() const { return registry_key(kSecret, peer_lines_); }
  [[nodiscard]] const std::vector<std::string>& peer_lines() const { return peer_lines_; }
  static std::string id(int i) { return "h" + std::to_string(i + 1); }
  ManagerUnderTest& host(int i) { return *hosts_.at(static_cast<std::size_t>(i)); }
  [[nodiscard]] int registry_port(int i) const { return registry_ports_.at(static_cast<std::size_t>(i)); }

  // (Re)starts host i on its data folder.
  void start(int i) {
    const auto index = static_cast<std::size_t>(i);
    hosts_[index].reset();
    hosts_[index] = std::make_unique<ManagerUnderTest>(
        data_[index]->path(),
        rfbsim::test::without_abuse_limits(
            {"--host-id", id(i), "--cluster-peers", peers_, "--cluster-secret-file", secret_file_,
             "--session-kind", "rfb", "--session-command", RFBSIM_MINIMAL, "--session-arg", "{port}",
             "--scenarios", "demo", "--max-sessions", std::to_string(max_sessions_), "--admin-token",
             kAdminToken}));
  }

  // kill -9: its sessions die with it (PR_SET_PDEATHSIG).
  void kill(int i) { host(i).process().stop(SIGKILL, 5s); }

  // The rows of `uid` in every host's index (read from its file, whether the host runs or not).
  std::vector<std::pair<int, rfbsim::test::IndexRow>> rows_of(const std::string& uid) {
    std::vector<std::pair<int, rfbsim::test::IndexRow>> out;
    for (int i = 0; i < count_; ++i) {
      for (const auto& row : host(i).index_rows()) {
        if (row.uid == uid) out.emplace_back(i, row);
      }
    }
    return out;
  }

  // The value host i's acceptor accepted for `uid` ("" when none), read from its sessions.db.
  std::string accepted_value(int i, const std::string& uid) {
    const std::string path = (data_.at(static_cast<std::size_t>(i))->path() / "sessions.db").string();
    sqlite3* db = nullptr;
    std::string value;
    if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
      sqlite3_stmt* select = nullptr;
      if (sqlite3_prepare_v2(db, "SELECT accepted_value FROM uid_acceptors WHERE uid = ?", -1, &select, nullptr) ==
          SQLITE_OK) {
        sqlite3_bind_text(select, 1, uid.c_str(), -1, SQLITE_TRANSIENT);
        if (sqlite3_step(select) == SQLITE_ROW && sqlite3_column_text(select, 0) != nullptr) {
          value = reinterpret_cast<const char*>(sqlite3_column_text(select, 0));
        }
      }
      sqlite3_finalize(select);
    }
    sqlite3_close(db);
    return value;
  }

  // GET of a Location the balancer would route by its /hN prefix.
  net::HttpResponse follow(const net::HttpResponse& redirect) {
    const std::string& location = redirect.headers.at("location");
    REQUIRE(location.size() > 4);
    REQUIRE(location.rfind("/h", 0) == 0);
    const int i = location[2] - '1';
    return host(i).get(location);
  }

 private:
  int count_;
  int max_sessions_;
  TempDir secret_dir_{"rfbsim-registry-secret"};
  std::string secret_file_;
  std::string peers_;
  std::vector<std::string> peer_lines_;
  std::vector<int> registry_ports_;
  std::vector<std::unique_ptr<TempDir>> data_;
  std::vector<std::unique_ptr<ManagerUnderTest>> hosts_;
};

// The token in a 302 to /hN/s/<token>/ ("" for anything else).
std::string token_of(const net::HttpResponse& response, const std::string& host_id) {
  if (response.status != 302) return "";
  const std::string& location = response.headers.at("location");
  const std::string prefix = "/" + host_id + "/s/";
  if (location.rfind(prefix, 0) != 0 || location.size() != prefix.size() + 33) return "";
  return location.substr(prefix.size(), 32);
}

}  // namespace

TEST_CASE("a uid's first host keeps it, and the other hosts send its participant there", "[manager][registry]") {
  Cluster cluster;
  const auto first = cluster.host(1).start("uid=reg-x&scenario=demo");
  const std::string token = token_of(first, "h2");
  REQUIRE(token.size() == 32);

  for (const int other : {0, 2}) {
    const auto moved = cluster.host(other).start("uid=reg-x&scenario=demo");
    REQUIRE(moved.status == 303);
    CHECK(moved.headers.at("location") == "/h2/start?uid=reg-x&scenario=demo");
    // Following it reaches the same session.
    CHECK(token_of(cluster.follow(moved), "h2") == token);
  }
  const auto rows = cluster.rows_of("reg-x");
  REQUIRE(rows.size() == 1);
  CHECK(rows.front().first == 1);
}

TEST_CASE("concurrent starts of one uid on every host make exactly one session", "[manager][registry]") {
  Cluster cluster;
  for (int round = 0; round < 6; ++round) {
    const std::string uid = "reg-race-" + std::to_string(round);
    std::atomic<int> ready{0};
    std::vector<net::HttpResponse> responses(3);
    std::vector<std::thread> threads;
    for (int i = 0; i < 3; ++i) {
      threads.emplace_back([&, i] {
        ++ready;
        while (ready.load() < 3) std::this_thread::yield();
        responses[static_cast<std::size_t>(i)] = cluster.host(i).start("uid=" + uid + "&scenario=demo");
      });
    }
    for (auto& thread : threads) thread.join();
    const auto rows = cluster.rows_of(uid);
    CAPTURE(uid);
    REQUIRE(rows.size() == 1);
    const std::string home = Cluster::id(rows.front().first);
    for (int i = 0; i < 3; ++i) {
      const auto& response = responses[static_cast<std::size_t>(i)];
      CAPTURE(i, response.status);
      if (Cluster::id(i) == home) {
        CHECK(token_of(response, home) == rows.front().second.token);
      } else {
        // Another host either redirected to the home, or (too few answers at that moment) asked for a retry.
        const bool redirected =
            response.status == 303 && response.headers.at("location").rfind("/" + home + "/", 0) == 0;
        CHECK((redirected || response.status == 503));
      }
    }
  }
}

TEST_CASE("a killed home keeps its uids, and after its restart a completed uid is completed everywhere",
          "[manager][registry]") {
  Cluster cluster;
  // A live session on h2, and one that is completed: a participant saw it, then it was ended.
  const std::string live = token_of(cluster.host(1).start("uid=reg-live&scenario=demo"), "h2");
  const std::string done = token_of(cluster.host(1).start("uid=reg-done&scenario=demo"), "h2");
  REQUIRE(live.size() == 32);
  REQUIRE(done.size() == 32);
  REQUIRE(cluster.host(1).wait_for_state(done, "running"));
  {
    const std::string url = "ws://127.0.0.1:" + std::to_string(cluster.host(1).port()) + "/h2/s/" + done + "/ws";
    rfbsim::test::WsRfbBridge bridge(url);
    rfbsim::test::RfbTestClient client("127.0.0.1", bridge.port());
    REQUIRE(client.wait_for_updates(1, 20s));
    REQUIRE(client.pump_until(
        [&] {
          const auto spent = cluster.host(1).row_for_token(done);
          return spent && !spent->spent_at.empty();
        },
        20s));
    const auto row = cluster.host(1).row_for_token(done);
    REQUIRE(row);
    REQUIRE(cluster.host(1).end_session(row->id, kAdminToken).status == 200);
    REQUIRE(cluster.host(1).wait_for_state(done, "ended"));
  }

  cluster.kill(1);
  for (const char* uid : {"reg-live", "reg-done"}) {
    for (const int other : {0, 2}) {
      const auto moved = cluster.host(other).start(std::string("uid=") + uid + "&scenario=demo");
      CAPTURE(uid, other);
      CHECK(moved.status == 303);
      CHECK(moved.headers.at("location").rfind("/h2/start?", 0) == 0);
    }
    CHECK(cluster.rows_of(uid).size() == 1);  // nothing new on h1 or h3
  }

  cluster.start(1);  // same data folder, same registry port
  for (int i = 0; i < 3; ++i) {
    auto response = cluster.host(i).start("uid=reg-done&scenario=demo");
    if (response.status == 303) response = cluster.follow(response);
    CAPTURE(i);
    CHECK(response.status == 409);
  }
  for (const auto& [host, r] : cluster.rows_of("reg-live")) CHECK(host == 1);
}

TEST_CASE("with two of three hosts down a new uid is asked to retry and nothing starts", "[manager][registry]") {
  Cluster cluster;
  cluster.kill(1);
  cluster.kill(2);
  const auto response = cluster.host(0).start("uid=reg-alone&scenario=demo");
  CHECK(response.status == 503);
  CHECK(response.headers.at("retry-after") == "5");
  CHECK(response.body.find("try again") != std::string::npos);
  CHECK(cluster.host(0).index_rows().empty());
}

TEST_CASE("a full or drained host sends a uid that lives elsewhere to its home, and claims no new uid",
          "[manager][registry]") {
  Cluster cluster(3, 1);  // one slot each: a host with one live session is full
  const std::string home_token = token_of(cluster.host(1).start("uid=reg-elsewhere&scenario=demo"), "h2");
  REQUIRE(home_token.size() == 32);
  REQUIRE(token_of(cluster.host(0).start("uid=reg-filler&scenario=demo"), "h1").size() == 32);
  auto claimed_nowhere = [&](const std::string& uid) {
    CHECK(cluster.rows_of(uid).empty());
    for (int i = 0; i < 3; ++i) {
      CAPTURE(uid, i);
      CHECK(cluster.accepted_value(i, uid).empty());
    }
  };

  // h1 is full: a uid whose home is h2 goes there (as a participant whose link the pool sent here would),
  // and its session is the one h2 has.
  const auto moved = cluster.host(0).start("uid=reg-elsewhere&scenario=demo");
  REQUIRE(moved.status == 303);
  CHECK(moved.headers.at("location") == "/h2/start?uid=reg-elsewhere&scenario=demo");
  CHECK(token_of(cluster.follow(moved), "h2") == home_token);
  // A new uid gets the busy page, and no host records a home for it.
  const auto busy = cluster.host(0).start("uid=reg-fresh&scenario=demo");
  CHECK(busy.status == 503);
  CHECK(busy.headers.count("retry-after") == 1);
  CHECK(busy.body.find("All simulators are busy") != std::string::npos);
  claimed_nowhere("reg-fresh");

  // A home decided for full h1 whose session never started (accepted by h1 and h2, forged here): h1 has no
  // room, so busy; full h2 learns it and sends the participant to h1.
  const std::string key = cluster.key();
  const std::string now = std::to_string(unix_now());
  for (int i = 0; i < 2; ++i) {
    const std::string id = Cluster::id(i);
    const std::string text = "accept reg-owned 1 h1 " + id + " fedcba9876543210 " + now + " h1";
    REQUIRE(ask_registry(cluster.registry_port(i), signed_line(key, text)) ==
            signed_line(key, "accepted reg-owned 1 h1 " + id + " fedcba9876543210"));
  }
  CHECK(cluster.host(0).start("uid=reg-owned&scenario=demo").status == 503);
  const auto to_owner = cluster.host(1).start("uid=reg-owned&scenario=demo");
  CHECK(to_owner.status == 303);
  CHECK(to_owner.headers.at("location") == "/h1/start?uid=reg-owned&scenario=demo");
  CHECK(cluster.rows_of("reg-owned").empty());

  // h3 has a free slot but is drained by the operator: the same answers.
  REQUIRE(admin_post(cluster.host(2), "/api/drain").status == 200);
  const auto drained_moved = cluster.host(2).start("uid=reg-elsewhere&scenario=demo");
  CHECK(drained_moved.status == 303);
  CHECK(drained_moved.headers.at("location") == "/h2/start?uid=reg-elsewhere&scenario=demo");
  const auto drained_busy = cluster.host(2).start("uid=reg-fresh&scenario=demo");
  CHECK(drained_busy.status == 503);
  CHECK(drained_busy.body.find("All simulators are busy") != std::string::npos);
  claimed_nowhere("reg-fresh");

  // Taking new sessions again, h3 claims the fresh uid for itself: nothing earlier had claimed it elsewhere.
  REQUIRE(admin_post(cluster.host(2), "/api/undrain").status == 200);
  CHECK(token_of(cluster.host(2).start("uid=reg-fresh&scenario=demo"), "h3").size() == 32);
  const auto rows = cluster.rows_of("reg-fresh");
  REQUIRE(rows.size() == 1);
  CHECK(rows.front().first == 2);
}

TEST_CASE("the registry port refuses forged, stale, misaddressed, foreign-list, malformed and overlong lines",
          "[manager][registry]") {
  Cluster cluster;
  const int port = cluster.registry_port(0);  // h1's acceptor
  const std::string key = cluster.key();
  const std::string now = std::to_string(unix_now());
  const std::string nonce = "0123456789abcdef";
  auto prepare = [&](const std::string& signing_key, const std::string& counter, const std::string& proposer,
                     const std::string& acceptor, const std::string& time) {
    return signed_line(signing_key, "prepare reg-forged " + counter + " " + proposer + " " + acceptor + " " + nonce +
                                        " " + time);
  };
  CHECK(ask_registry(port, prepare(registry_key("a-forged-secret-0123456789", cluster.peer_lines()), "5", "h3", "h1",
                                   now)) == "error bad hmac\n");
  // The right secret on another peer list (a host started before a change of the list): another key.
  auto other_list = cluster.peer_lines();
  other_list.push_back("h4=127.0.0.1:1");
  CHECK(ask_registry(port, prepare(registry_key(kSecret, other_list), "5", "h3", "h1", now)) == "error bad hmac\n");
  CHECK(ask_registry(port, prepare(key, "5", "h3", "h1", std::to_string(unix_now() - 600))) == "error stale time\n");
  CHECK(ask_registry(port, prepare(key, "5", "h3", "h2", now)) == "error not acceptor h2\n");
  CHECK(ask_registry(port, prepare(key, "5", "h9", "h1", now)) == "error proposer not a peer\n");
  CHECK(ask_registry(port, "hello\n").rfind("error ", 0) == 0);
  CHECK(ask_registry(port, std::string(600, 'x') + "\n") == "error line too long\n");

  // None of those changed anything: a real prepare finds nothing promised or accepted.
  CHECK(ask_registry(port, prepare(key, "1", "h3", "h1", now)) ==
        signed_line(key, "promise reg-forged 1 h3 h1 " + nonce + " 0 - -"));
  CHECK(ask_registry(port, signed_line(key, "accept reg-forged 1 h3 h1 " + nonce + " " + now + " h3")) ==
        signed_line(key, "accepted reg-forged 1 h3 h1 " + nonce));
  // A lower ballot is refused with the promise that outranks it; a higher one learns the accepted value.
  CHECK(ask_registry(port, prepare(key, "1", "h2", "h1", now)) ==
        signed_line(key, "reject reg-forged 1 h2 h1 " + nonce + " 1 h3"));
  CHECK(ask_registry(port, prepare(key, "2", "h2", "h1", now)) ==
        signed_line(key, "promise reg-forged 2 h2 h1 " + nonce + " 1 h3 h3"));
  // The manager carries on.
  CHECK(cluster.host(0).get("/healthz").status == 200);
}

TEST_CASE("two hosts down in turn lock no uid out: once both are up, it starts on one of them",
          "[manager][registry]") {
  Cluster cluster(2);
  // h2 down: h1 alone is no majority of two, so nothing is accepted anywhere.
  cluster.kill(1);
  CHECK(cluster.host(0).start("uid=reg-pair&scenario=demo").status == 503);
  // Then h1 down and h2 back: the same on h2.
  cluster.start(1);
  cluster.kill(0);
  CHECK(cluster.host(1).start("uid=reg-pair&scenario=demo").status == 503);
  cluster.start(0);

  // A split as the first-answer-wins registry could leave it: each acceptor accepted its own host.
  const std::string key = cluster.key();
  const std::string now = std::to_string(unix_now());
  for (int i = 0; i < 2; ++i) {
    const std::string id = Cluster::id(i);
    const std::string text = "accept reg-split 1 " + id + " " + id + " fedcba9876543210 " + now + " " + id;
    REQUIRE(ask_registry(cluster.registry_port(i), signed_line(key, text)) ==
            signed_line(key, "accepted reg-split 1 " + id + " " + id + " fedcba9876543210"));
  }

  for (const char* uid : {"reg-pair", "reg-split"}) {
    CAPTURE(uid);
    const std::string query = std::string("uid=") + uid + "&scenario=demo";
    auto first = cluster.host(0).start(query);
    if (first.status == 303) first = cluster.follow(first);
    REQUIRE(first.status == 302);
    const auto rows = cluster.rows_of(uid);
    REQUIRE(rows.size() == 1);
    const std::string home = Cluster::id(rows.front().first);
    if (std::string(uid) == "reg-split") CHECK(home == "h2");  // the higher of the two accepted ballots, 1.h2
    // The other host agrees.
    auto second = cluster.host(1).start(query);
    if (second.status == 303) second = cluster.follow(second);
    CHECK(token_of(second, home) == rows.front().second.token);
    CHECK(cluster.rows_of(uid).size() == 1);
  }
}

TEST_CASE("a cluster of one host decides alone", "[manager][registry]") {
  Cluster cluster(1);
  const std::string token = token_of(cluster.host(0).start("uid=reg-one&scenario=demo"), "h1");
  CHECK(token.size() == 32);
  CHECK(token_of(cluster.host(0).start("uid=reg-one&scenario=demo"), "h1") == token);
  CHECK(cluster.rows_of("reg-one").size() == 1);
}

TEST_CASE("duelling proposers: many fresh uids started at once on every host get one session each",
          "[manager][registry]") {
  Cluster cluster;
  constexpr int kUids = 8;
  std::atomic<int> ready{0};
  std::vector<std::vector<net::HttpResponse>> responses(kUids, std::vector<net::HttpResponse>(3));
  std::vector<std::thread> threads;
  for (int u = 0; u < kUids; ++u) {
    for (int i = 0; i < 3; ++i) {
      threads.emplace_back([&, u, i] {
        ++ready;
        while (ready.load() < 3 * kUids) std::this_thread::yield();
        const std::string query = "uid=reg-duel-" + std::to_string(u) + "&scenario=demo";
        // As a participant would: a 503 (no ballot reached a majority) is tried again in a moment.
        net::HttpResponse response;
        for (int attempt = 0; attempt < 10; ++attempt) {
          response = cluster.host(i).start(query);
          if (response.status != 503) break;
          std::this_thread::sleep_for(200ms);
        }
        if (response.status == 303) response = cluster.follow(response);
        responses[static_cast<std::size_t>(u)][static_cast<std::size_t>(i)] = response;
      });
    }
  }
  for (auto& thread : threads) thread.join();
  for (int u = 0; u < kUids; ++u) {
    const std::string uid = "reg-duel-" + std::to_string(u);
    CAPTURE(uid);
    const auto rows = cluster.rows_of(uid);
    REQUIRE(rows.size() == 1);
    const std::string home = Cluster::id(rows.front().first);
    for (int i = 0; i < 3; ++i) {
      CAPTURE(i);
      CHECK(token_of(responses[static_cast<std::size_t>(u)][static_cast<std::size_t>(i)], home) ==
            rows.front().second.token);
    }
  }
}

TEST_CASE("two new uids racing for a host's last slot: the one left out is homed nowhere, and starts elsewhere",
          "[manager][registry]") {
  Cluster cluster(3, 1);  // one slot each
  for (int round = 0; round < 4; ++round) {
    const std::string first = "reg-slot-a" + std::to_string(round), second = "reg-slot-b" + std::to_string(round);
    std::atomic<int> ready{0};
    std::vector<net::HttpResponse> responses(2);
    std::vector<std::thread> threads;
    for (int k = 0; k < 2; ++k) {
      threads.emplace_back([&, k] {
        ++ready;
        while (ready.load() < 2) std::this_thread::yield();
        responses[static_cast<std::size_t>(k)] =
            cluster.host(0).start("uid=" + (k == 0 ? first : second) + "&scenario=demo");
      });
    }
    for (auto& thread : threads) thread.join();
    // One of them has h1's slot; the other was never homed on h1 (a claim in flight holds the slot it would
    // take), so it got the busy page and no host accepted a home for it.
    const int winner = responses[0].status == 302 ? 0 : 1;
    const std::string left_out = winner == 0 ? second : first;
    CAPTURE(round, responses[0].status, responses[1].status);
    REQUIRE(responses[static_cast<std::size_t>(winner)].status == 302);
    CHECK(responses[static_cast<std::size_t>(1 - winner)].status == 503);
    for (int i = 0; i < 3; ++i) CHECK(cluster.accepted_value(i, left_out).empty());
    // Where there is room it starts, as the balancer would send it there next.
    const int elsewhere = 1 + round % 2;
    CHECK(token_of(cluster.host(elsewhere).start("uid=" + left_out + "&scenario=demo"), Cluster::id(elsewhere))
              .size() == 32);
    // Free every slot for the next round.
    for (int i = 0; i < 3; ++i) {
      for (const auto& row : cluster.host(i).index_rows()) {
        if (row.state == "running" || row.state == "starting") cluster.host(i).end_session(row.id, kAdminToken);
      }
    }
    const auto bearer = std::string("Bearer ") + kAdminToken;
    for (int i = 0; i < 3; ++i) {
      REQUIRE(rfbsim::test::eventually(
          [&] { return cluster.host(i).get("/api/host", {{"Authorization", bearer}}).body.find("\"live\":0") != std::string::npos; },
          20s));
    }
  }
}
