// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager against abuse on its public port, with real processes and real sockets on loopback: previews
// that must not spend a link, a /start storm, upgrade floods, idle and slowly trickling connections, a second
// browser taking a session over, and X-Forwarded-For from a trusted front end only. Each time a real
// participant from another address still starts and gets pictures.
#include <catch2/catch.hpp>

#include <string>

#include "abuse_clients.hpp"
#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "skip.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
namespace abuse = rfbsim::test::abuse;

namespace {

// A participant that /start-s from `source` (the WebSocket comes from 127.0.0.1 through the bridge, as a
// browser's may come from another address than its /start) and gets `pictures` framebuffer updates.
bool participant_gets_pictures(const ManagerUnderTest& manager, const std::string& source, const std::string& uid,
                               int pictures = 2) {
  const auto start = abuse::request_from(source, manager.port(), abuse::raw_request("GET", "/start?uid=" + uid,
                                                                                    manager.port()));
  const std::string token = token_from_redirect(start);
  if (token.empty()) {
    UNSCOPED_INFO("the participant's /start from " << source << " got " << start.status);
    return false;
  }
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  return client.wait_for_updates(static_cast<std::uint64_t>(pictures), 30s);
}

// The Retry-After of a 429 as a number of seconds (0 when missing or not a number).
long retry_after(const rfbsim::test::net::HttpResponse& response) {
  const auto it = response.headers.find("retry-after");
  if (it == response.headers.end()) return 0;
  try {
    return std::stol(it->second);
  } catch (const std::exception&) {
    return 0;
  }
}

// N idle connections from one address: only the per-address cap is let in, the rest is closed at accept, and
// a participant from elsewhere is served as usual while the manager sits idle.
void idle_flood(int count) {
  // This process holds every flood socket; the manager inherits the limit and sizes its total cap from it.
  if (!abuse::raise_descriptor_limit(static_cast<std::uint64_t>(count) + 512)) {
    RFBSIM_SKIP("the descriptor limit cannot be raised to " + std::to_string(count + 512) +
                " (ulimit -Hn; root may raise it)");
  }
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({}));
  constexpr int kPerAddress = 64;  // --max-connections-per-address's default
  // Not from 127.0.0.1: the test's own helpers (metrics, the bridge) come from there and must get through.
  abuse::LowDescriptorReserve for_the_participant(128);
  const auto opening = std::chrono::steady_clock::now();
  abuse::IdleConnections flood("127.0.0.3", manager.port(), count);
  const auto open_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - opening).count();
  // Those admitted are closed by the 5 s handshake timeout, and their places go to later ones: each 5 s that
  // opening took lets at most one more cap's worth in (on an idle machine opening takes well under 5 s).
  const int admitted_at_most = kPerAddress * (1 + static_cast<int>(open_ms / 5000));
  INFO(count << " connections opened in " << open_ms << " ms");
  const std::string refused = "rfbsim_rejections_total{reason=\"connection_limit\"}";
  CHECK(rfbsim::test::eventually([&] { return manager.metric(refused) >= count - admitted_at_most; }, 30s));
  // The metrics request itself is the only other connection open now.
  CHECK(manager.metric("rfbsim_connections") <= kPerAddress + 1);
  CHECK(rfbsim::test::eventually([&] { return flood.closed() >= count - admitted_at_most; }, 30s));

  // While they sit there the manager does nothing: far from a core (a spin would use all of one).
  const double cpu_before = abuse::process_cpu_seconds(manager.pid());
  std::this_thread::sleep_for(2s);
  const double cpu_used = abuse::process_cpu_seconds(manager.pid()) - cpu_before;
  INFO("the manager used " << cpu_used << " s of CPU in 2 s");
  CHECK(cpu_used < 0.5);

  for_the_participant.release();
  CHECK(participant_gets_pictures(manager, "127.0.0.2", "idle-flood-real"));
  CHECK(manager.get("/healthz").status == 200);
}

}  // namespace

TEST_CASE("HEAD /start starts nothing, and the real GET afterwards starts and streams", "[manager][abuse]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({}));
  const auto head = rfbsim::test::net::http_request(
      manager.port(), abuse::raw_request("HEAD", "/start?uid=preview-1", manager.port()));
  CHECK(head.status == 200);
  CHECK(head.body.empty());
  CHECK(head.headers.count("location") == 0);
  // Nothing started, nothing recorded: the link is as good as new.
  CHECK(manager.children().empty());
  CHECK(manager.index_rows().empty());
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"head_preview\"}") == 1);

  const std::string token = token_from_redirect(manager.start("uid=preview-1"));
  REQUIRE(token.size() == 32);
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(2, 30s));
  CHECK(manager.index_rows().size() == 1);
}

TEST_CASE("a link only probed by GET is abandoned at the idle timeout and starts again, a seen one is spent",
          "[manager][abuse]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--idle-timeout-s", "1"}));

  SECTION("probed: the page and its status fetched, no WebSocket") {
    const std::string token = token_from_redirect(manager.start("uid=probe-1"));
    REQUIRE(token.size() == 32);
    CHECK(manager.get("/s/" + token + "/").status == 200);
    CHECK(manager.get("/s/" + token + "/status").status == 200);
    REQUIRE(manager.wait_for_state(token, "abandoned", 30s));
    CHECK(abuse::index_column(data.path(), token, "spent_at").empty());
    const std::string again = token_from_redirect(manager.start("uid=probe-1"));
    CHECK(again.size() == 32);
    CHECK(again != token);
  }

  SECTION("seen: a picture reached the participant, the session ends idle, and the link is used up") {
    const std::string token = token_from_redirect(manager.start("uid=seen-1"));
    REQUIRE(token.size() == 32);
    {
      WsRfbBridge bridge(manager.ws_url(token));
      RfbTestClient client("127.0.0.1", bridge.port());
      REQUIRE(client.wait_for_updates(2, 30s));
      CHECK(rfbsim::test::eventually([&] { return !abuse::index_column(data.path(), token, "spent_at").empty(); },
                                     10s));
    }
    REQUIRE(manager.wait_for_state(token, "idle", 30s));
    const auto again = manager.start("uid=seen-1");
    CHECK(again.status == 409);
  }
}

TEST_CASE("a /start storm from one address gets the unspent cap then 429s, and another address still starts",
          "[manager][abuse]") {
  TempDir data;
  // Room for the storm's unspent sessions and the real participant: only the per-address limits stop it.
  ManagerUnderTest manager(data.path(), with_small_sessions({"--max-sessions", "5"}));
  constexpr int kStorm = 300;
  constexpr int kUnspentCap = 3;  // --max-unspent-sessions-per-address's default
  int started = 0;
  int limited = 0;
  int without_retry_after = 0;
  for (int i = 0; i < kStorm; ++i) {
    const auto response = manager.start("uid=storm-" + std::to_string(i));
    if (response.status == 302) ++started;
    if (response.status == 429) {
      ++limited;
      if (retry_after(response) < 1) ++without_retry_after;
    }
  }
  CHECK(started == kUnspentCap);
  CHECK(limited == kStorm - kUnspentCap);
  CHECK(without_retry_after == 0);
  const double rate_limited = manager.metric("rfbsim_rejections_total{reason=\"rate_limited\"}");
  const double unspent = manager.metric("rfbsim_rejections_total{reason=\"unspent_limit\"}");
  CHECK(rate_limited > 0);
  CHECK(rate_limited + unspent == kStorm - kUnspentCap);
  CHECK(manager.children().size() == kUnspentCap);

  CHECK(participant_gets_pictures(manager, "127.0.0.2", "storm-real"));
}

TEST_CASE("WebSocket upgrades beyond the burst get 429 with Retry-After, per address", "[manager][abuse]") {
  TempDir data;
  ManagerUnderTest manager(data.path(),
                           with_small_sessions({"--rate-upgrade-burst", "3", "--rate-upgrade-per-minute", "1"}));
  // No such session: each upgrade the limiter lets through is answered 404 by the next check.
  const std::string target = "/s/0123456789abcdef0123456789abcdef/ws";
  const std::string upgrade = abuse::upgrade_request(target, manager.port(), manager.origin());
  for (int i = 0; i < 3; ++i) CHECK(abuse::request_from("127.0.0.2", manager.port(), upgrade).status == 404);
  for (int i = 0; i < 2; ++i) {
    const auto refused = abuse::request_from("127.0.0.2", manager.port(), upgrade);
    CHECK(refused.status == 429);
    CHECK(retry_after(refused) >= 1);
  }
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"rate_limited\"}") == 2);
  // Another address has a bucket of its own: a participant's browser from 127.0.0.1 connects and streams.
  CHECK(abuse::request_from("127.0.0.3", manager.port(), upgrade).status == 404);
  CHECK(participant_gets_pictures(manager, "127.0.0.1", "upgrade-real"));
}

TEST_CASE("300 idle connections from one address: only the per-address cap stays open", "[manager][abuse]") {
  idle_flood(300);
}

TEST_CASE("2000 idle connections from one address: only the per-address cap stays open", "[manager][flood][.]") {
  idle_flood(2000);
}

TEST_CASE("slowloris connections are closed by the handshake timeout while another address is served",
          "[manager][abuse][waits]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({}));
  constexpr int kSlow = 20;
  abuse::SlowHeaderClients slow("127.0.0.3", manager.port(), kSlow);
  // Served meanwhile: the health check and a participant.
  CHECK(manager.get("/healthz").status == 200);
  CHECK(participant_gets_pictures(manager, "127.0.0.2", "slowloris-real"));
  // Each sent a line a second and still lost its connection to the 5 s limit on the whole head.
  CHECK(rfbsim::test::eventually([&] { return slow.closed() == kSlow; }, 30s));
  INFO("the longest slow connection stayed open " << slow.longest_open().count() << " ms; " << slow.lines_sent()
                                                  << " header lines were sent after the first");
  CHECK(slow.lines_sent() >= kSlow);  // they did trickle before being cut off
  CHECK(slow.longest_open() < 20s);   // not left to live for as long as they keep typing
}

TEST_CASE("a second participant browser takes the session over and the first is told why", "[manager][abuse]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({}));
  const std::string token = token_from_redirect(manager.start("uid=takeover-1"));
  REQUIRE(token.size() == 32);
  WsRfbBridge first_bridge(manager.ws_url(token));
  RfbTestClient first("127.0.0.1", first_bridge.port());
  REQUIRE(first.wait_for_updates(1, 30s));

  WsRfbBridge second_bridge(manager.ws_url(token));
  RfbTestClient second("127.0.0.1", second_bridge.port());
  REQUIRE(first_bridge.wait_last_finished(10s));
  CHECK(first_bridge.last_close_code() == 4001);
  CHECK(first_bridge.last_close_reason() == "opened in another window");
  CHECK(second.wait_for_updates(2, 30s));
  CHECK(manager.metric("rfbsim_takeovers_total") == 1);
  CHECK(manager.state_of(token) == "running");
}

TEST_CASE("X-Forwarded-For counts per forwarded address only from a trusted proxy", "[manager][abuse]") {
  TempDir data;
  // A burst of 2 and almost no refill; the requests carry no uid, so each costs a token and is then refused
  // 400 without starting anything.
  const std::vector<std::string> tight = {"--rate-start-burst", "2", "--rate-start-per-minute", "1"};
  const auto forwarded_start = [](const ManagerUnderTest& manager, int client) {
    return rfbsim::test::net::http_request(
        manager.port(), abuse::raw_request("GET", "/start?no-uid=1", manager.port(),
                                           {{"X-Forwarded-For", "203.0.113." + std::to_string(client)}}));
  };

  SECTION("behind a trusted proxy each participant has a bucket of their own") {
    auto flags = tight;
    flags.insert(flags.end(), {"--trusted-proxies", "127.0.0.1"});
    ManagerUnderTest manager(data.path(), with_small_sessions(flags));
    for (int client = 1; client <= 5; ++client) {
      CHECK(forwarded_start(manager, client).status == 400);
      CHECK(forwarded_start(manager, client).status == 400);
      CHECK(forwarded_start(manager, client).status == 429);
    }
    CHECK(manager.metric("rfbsim_rejections_total{reason=\"rate_limited\"}") == 5);
  }

  SECTION("behind a trusted proxy an IPv6 participant's whole /64 shares one bucket") {
    auto flags = tight;
    flags.insert(flags.end(), {"--trusted-proxies", "127.0.0.1"});
    ManagerUnderTest manager(data.path(), with_small_sessions(flags));
    const auto from = [&](const std::string& address) {
      return rfbsim::test::net::http_request(
                 manager.port(),
                 abuse::raw_request("GET", "/start?no-uid=1", manager.port(), {{"X-Forwarded-For", address}}))
          .status;
    };
    // A fresh address from the same /64 each time does not buy a fresh allowance; the next /64 has its own.
    CHECK(from("2001:db8:1:2::1") == 400);
    CHECK(from("2001:db8:1:2::2") == 400);
    CHECK(from("2001:db8:1:2:ffff::3") == 429);
    CHECK(from("2001:db8:1:3::1") == 400);
  }

  SECTION("from anyone else the header is ignored: one address, one bucket") {
    ManagerUnderTest manager(data.path(), with_small_sessions(tight));
    CHECK(forwarded_start(manager, 1).status == 400);
    CHECK(forwarded_start(manager, 2).status == 400);
    for (int client = 3; client <= 10; ++client) CHECK(forwarded_start(manager, client).status == 429);
    CHECK(manager.metric("rfbsim_rejections_total{reason=\"rate_limited\"}") == 8);
  }
}
