// SPDX-License-Identifier: GPL-2.0-or-later
// Participants' addresses behind HAProxy: the session's data and the host's session index record the
// participant's address hash (from the X-Forwarded-For HAProxy adds, which the managers trust), not the
// balancer's; per-address limits count each participant apart (--rate-limit); and the hosts' data dirs make
// one report with no duplicate uid.
#include <catch2/catch.hpp>
#include <sqlite3.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cluster_under_test.hpp"
#include "record/digest.hpp"
#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "source_forwarder.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ClusterUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::SourceForwarder;
using rfbsim::test::StartResult;
using rfbsim::test::WsRfbBridge;

namespace {

constexpr const char* kAddressKey = "cluster-address-key-for-the-test";

// The session folder of `uid` in a host's data dir ("" when none).
std::filesystem::path session_folder(const std::filesystem::path& data, const std::string& uid) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(data / "sessions", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > uid.size() && name.compare(name.size() - uid.size() - 1, std::string::npos, "-" + uid) == 0) {
      return entry.path();
    }
  }
  return {};
}

// The address of the first client connect event in a session's events.jsonl ("" when none yet).
std::string connect_address(const std::filesystem::path& folder) {
  std::ifstream events(folder / "events.jsonl");
  for (std::string line; std::getline(events, line);) {
    const auto event = nlohmann::json::parse(line, nullptr, false);
    if (!event.is_discarded() && event.value("type", "") == "client" && event.value("event", "") == "connect") {
      return event.value("address", "");
    }
  }
  return "";
}

// The address_hash column of `uid`'s newest session in a host's index, read with a connection of our own
// ("?" when there is no such row).
std::string index_address_hash(const std::filesystem::path& data, const std::string& uid) {
  sqlite3* db = nullptr;
  const std::string path = (data / "sessions.db").string();
  REQUIRE(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  REQUIRE(sqlite3_prepare_v2(db, "SELECT address_hash FROM sessions WHERE uid = ? ORDER BY id DESC LIMIT 1", -1,
                             &stmt, nullptr) == SQLITE_OK);
  sqlite3_bind_text(stmt, 1, uid.c_str(), -1, SQLITE_TRANSIENT);
  std::string hash = "?";
  if (sqlite3_step(stmt) == SQLITE_ROW) hash = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return hash;
}

// Opens session `started` through `via` (a forwarder to HAProxy) and waits for a few pictures.
void watch(const StartResult& started, int via) {
  WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(via) + "/" + started.host + "/s/" + started.token + "/ws");
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(3, 30s));
}

}  // namespace

TEST_CASE("the participant's address and not the balancer's is hashed and limited and the merged report has no "
          "duplicate uid",
          "[cluster]") {
  ::setenv("RFBSIM_ADDRESS_KEY", kAddressKey, 1);  // inherited by the script, its managers and their sessions
  ClusterUnderTest cluster({.hosts = 3, .max_sessions = 1, .rate_limit = true,
                            .config_yaml = rfbsim::test::sim_rfb_sessions_yaml()});
  ::unsetenv("RFBSIM_ADDRESS_KEY");
  SourceForwarder from5("127.0.0.5", cluster.port());
  SourceForwarder from6("127.0.0.6", cluster.port());
  SourceForwarder from7("127.0.0.7", cluster.port());

  // A participant at 127.0.0.5: its session's connect event carries that address's hash.
  const StartResult first = cluster.start("uid=addr-1", "/start", from5.port());
  INFO(first.response.raw.substr(0, 300));
  REQUIRE(first.response.status == 302);
  watch(first, from5.port());
  const auto folder = session_folder(cluster.host(first.host).data, "addr-1");
  REQUIRE(!folder.empty());
  REQUIRE(rfbsim::test::eventually([&] { return !connect_address(folder).empty(); }, 10s));
  CHECK(connect_address(folder) == rfbsim::sim::hash_address(kAddressKey, "127.0.0.5"));
  CHECK(connect_address(folder) != rfbsim::sim::hash_address(kAddressKey, "127.0.0.1"));
  // The host's index names the same participant, so that index and events.jsonl can be joined.
  CHECK(index_address_hash(cluster.host(first.host).data, "addr-1") ==
        rfbsim::sim::hash_address(kAddressKey, "127.0.0.5"));

  // Per-address limits are the participant's: 127.0.0.6 re-opening its link too often is refused (429, the
  // /start burst is 10), while 127.0.0.7 behind the same balancer is not.
  const StartResult second = cluster.start("uid=addr-2", "/start", from6.port());
  REQUIRE(second.response.status == 302);
  const std::string path = "/" + second.host + "/start";
  int limited = 0;
  for (int i = 0; i < 14; ++i) limited += cluster.start("uid=addr-2", path, from6.port()).response.status == 429;
  CHECK(limited > 0);
  const StartResult other = cluster.start("uid=addr-2", path, from7.port());
  CHECK(other.response.status == 302);
  CHECK(other.token == second.token);
  watch(second, from7.port());

  // The sessions end and the cluster stops; the hosts' data dirs together make one report, no uid twice.
  CHECK(cluster.end_session(first.host, first.token));
  CHECK(cluster.end_session(second.host, second.token));
  cluster.stop();
  std::vector<std::string> args;
  for (const auto& host : cluster.hosts()) args.push_back(host.data.string());
  args.emplace_back("--out");
  args.push_back((cluster.run_dir() / "report").string());
  const auto report = rfbsim::test::run_to_exit(RFBSIM_SIM_REPORT, args, 60s);
  INFO(report.output);
  CHECK(WIFEXITED(report.status));
  CHECK(WEXITSTATUS(report.status) == 0);
  CHECK(report.output.find("duplicate uid") == std::string::npos);
  std::ifstream csv(cluster.run_dir() / "report" / "sessions.csv");
  std::string header, row;
  std::getline(csv, header);
  int rows = 0, addr1 = 0, addr2 = 0;
  while (std::getline(csv, row)) {
    ++rows;
    addr1 += row.find("addr-1") != std::string::npos;
    addr2 += row.find("addr-2") != std::string::npos;
  }
  CHECK(addr1 == 1);
  CHECK(addr2 == 1);
  CHECK(rows == 2);
}
