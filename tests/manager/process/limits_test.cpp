// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's limits with real sessions: at most N live sessions (the next participant gets the busy
// page), the maximum duration, the idle timeout, an administrator ending a session, and 200 start/end
// cycles that leave no process, descriptor or listening port behind.
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>
#include <thread>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
using rfbsim::test::WsRfbBridge;

namespace {


}  // namespace

TEST_CASE("the participant beyond the session limit gets the busy page, and a metric counts it", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--max-sessions", "2", "--admin-token", kAdminToken}));
  const std::string a = token_from_redirect(manager.start("uid=cap-a"));
  const std::string b = token_from_redirect(manager.start("uid=cap-b"));
  REQUIRE(a.size() == 32);
  REQUIRE(b.size() == 32);

  const auto busy = manager.start("uid=cap-c");
  CHECK(busy.status == 503);
  CHECK(busy.headers.at("retry-after") == "10");
  CHECK(busy.body.find("All simulators are busy") != std::string::npos);
  CHECK(busy.body.find("http-equiv=\"refresh\" content=\"10\"") != std::string::npos);
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"busy\"}") == 1);
  CHECK(manager.children().size() == 2);
  // Someone already in keeps their place.
  CHECK(token_from_redirect(manager.start("uid=cap-a")) == a);

  // A freed slot takes the next participant.
  const auto row = manager.row_for_token(a);
  REQUIRE(row);
  REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);
  REQUIRE(rfbsim::test::eventually([&] { return manager.start("uid=cap-c").status == 302; }, 10s));
  CHECK(manager.metric("rfbsim_sessions{state=\"running\"}") + manager.metric("rfbsim_sessions{state=\"starting\"}") == 2);
}

TEST_CASE("a session ends at its maximum duration and its browser is told so", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--max-duration-s", "3", "--idle-timeout-s", "3"}));
  const std::string token = token_from_redirect(manager.start("uid=expire-1"));
  REQUIRE(token.size() == 32);
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  // Keep reading frames until the manager ends the session.
  client.pump_until([&] { return !client.connected(); }, 15s);
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_close_code() == 1001);
  CHECK(bridge.last_close_reason() == "session expired");
  REQUIRE(manager.wait_for_state(token, "expired"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->detail == "reached the maximum duration of 3 s");
  CHECK_FALSE(rfbsim::test::process_exists(static_cast<pid_t>(row->pid)));
  // The link is used up: the same uid gets the completed page, the page and the socket say it ended.
  const auto again = manager.start("uid=expire-1");
  CHECK(again.status == 409);
  CHECK(again.body.find("Already completed") != std::string::npos);
  CHECK(manager.get("/s/" + token + "/").status == 410);
  WsRfbBridge late(manager.ws_url(token));
  CHECK_THROWS(RfbTestClient("127.0.0.1", late.port()));
  REQUIRE(late.wait_last_finished(5s));
  CHECK(late.last_handshake_status() == 410);
}

TEST_CASE("a session with no browser ends after the idle timeout, and not while one is connected", "[manager][waits]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--idle-timeout-s", "1"}));

  SECTION("nobody ever connects: abandoned, and the link may start again") {
    const std::string token = token_from_redirect(manager.start("uid=idle-1"));
    REQUIRE(manager.wait_for_state(token, "abandoned", 15s));
    const auto row = manager.row_for_token(token);
    REQUIRE(row);
    CHECK(row->detail == "no browser connected for 1 s");
    CHECK(manager.start("uid=idle-1").status == 302);
  }

  SECTION("a connected browser keeps it alive; leaving starts the clock") {
    const std::string token = token_from_redirect(manager.start("uid=idle-2"));
    {
      WsRfbBridge bridge(manager.ws_url(token));
      RfbTestClient client("127.0.0.1", bridge.port());
      REQUIRE(client.wait_for_updates(1, 20s));
      // Three idle timeouts with a viewer: still running (absence of an event can only be shown by waiting).
      client.pump_until([] { return false; }, 3s);
      CHECK(client.connected());
      CHECK(manager.state_of(token) == "running");
    }
    REQUIRE(manager.wait_for_state(token, "idle", 15s));
  }
}

TEST_CASE("a session no browser ever connected to ends at the first-connect timeout, long before the idle one",
          "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(),
                           with_small_sessions({"--idle-timeout-s", "600", "--first-connect-timeout-s", "1"}));
  const std::string token = token_from_redirect(manager.start("uid=preview-1"));
  REQUIRE(manager.wait_for_state(token, "abandoned", 15s));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->detail == "no browser connected within 1 s of the start");
  CHECK(manager.start("uid=preview-1").status == 302);  // the participant can still come
}

TEST_CASE("an administrator ends a session through the API, and only with the token", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--admin-token", kAdminToken}));
  const std::string token = token_from_redirect(manager.start("uid=admin-1"));
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  // The participant saw a picture (the link is spent), so the researcher's end counts as ended, not abandoned.
  REQUIRE(client.pump_until(
      [&] {
        const auto spent = manager.row_for_token(token);
        return spent && !spent->spent_at.empty();
      },
      20s));

  const std::string path = "/api/sessions/" + std::to_string(row->id) + "/end";
  const auto post = [&](const std::string& headers) {
    return rfbsim::test::net::http_request(
        manager.port(), "POST " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + headers +
                            "Content-Length: 0\r\nConnection: close\r\n\r\n");
  };
  const auto anonymous = post("");
  CHECK(anonymous.status == 401);
  CHECK(anonymous.headers.at("www-authenticate").find("Basic") != std::string::npos);
  CHECK(post("Authorization: Bearer wrong-token-wrong-token\r\nX-Rfbsim-Admin: 1\r\n").status == 401);
  CHECK(post("Authorization: Bearer " + std::string(kAdminToken) + "\r\n").status == 403);  // no CSRF header
  CHECK(manager.get("/api/sessions").status == 401);
  CHECK(manager.get("/admin").status == 401);

  // The list shows the live session with its token (the researcher may watch it).
  const auto list = manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + kAdminToken}});
  CHECK(list.status == 200);
  CHECK(list.body.find("\"uid\":\"admin-1\"") != std::string::npos);
  CHECK(list.body.find(token) != std::string::npos);

  CHECK(manager.end_session(row->id, kAdminToken).status == 200);
  REQUIRE(bridge.wait_last_finished(10s));
  CHECK(bridge.last_close_code() == 1001);
  CHECK(bridge.last_close_reason() == "session ended by the researcher");
  REQUIRE(manager.wait_for_state(token, "ended"));
  CHECK(manager.end_session(row->id, kAdminToken).status == 404);  // not live any more
  CHECK(manager.get("/s/" + token + "/").status == 410);
}

namespace {

// Starts and ends `kCycles` sessions one after another, and checks that nothing is left behind.
void check_start_end_cycles(const int kCycles) {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::without_abuse_limits(
                                            with_small_sessions({"--admin-token", kAdminToken, "--max-sessions", "1"})));
  std::set<int> session_ports;
  std::vector<pid_t> session_pids;
  int descriptors_after_first = 0;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    const std::string token = token_from_redirect(manager.start("uid=cycle-" + std::to_string(cycle)));
    REQUIRE(token.size() == 32);
    REQUIRE(manager.wait_for_state(token, "running"));
    const auto row = manager.row_for_token(token);
    REQUIRE(row);
    session_ports.insert(row->port);
    session_pids.push_back(static_cast<pid_t>(row->pid));
    REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);
    REQUIRE(manager.wait_for_state(token, "abandoned"));  // ended before any participant saw it
    if (cycle == 0) descriptors_after_first = manager.open_descriptors();
  }
  // The status poll that just returned may still hold its connection for a moment on the manager's side;
  // a leak never goes away, a closing connection does.
  INFO("descriptors after the first cycle " << descriptors_after_first << ", after the last "
                                            << manager.open_descriptors());
  CHECK(rfbsim::test::eventually([&] { return manager.open_descriptors() <= descriptors_after_first; }, 5s));
  CHECK(manager.children().empty());
  for (const pid_t pid : session_pids) CHECK_FALSE(rfbsim::test::process_exists(pid));
  // A session's port may be another test's by now: only one held by a process of a session's group is left behind.
  for (const int port : session_ports) {
    for (const pid_t group : rfbsim::test::listener_groups(port)) {
      INFO("port " << port << " is held by process group " << group);
      CHECK(std::find(session_pids.begin(), session_pids.end(), group) == session_pids.end());
    }
  }
  const auto rows = manager.index_rows();
  CHECK(rows.size() == static_cast<std::size_t>(kCycles));
  CHECK(std::all_of(rows.begin(), rows.end(), [](const auto& r) { return r.state == "abandoned"; }));
  CHECK(manager.metric("rfbsim_session_starts_total") == kCycles);
}

}  // namespace

// A leak of one descriptor or process per cycle shows after a few dozen; the 200 run is the heavy version, on
// demand with the floods (`ctest -L flood`), which keeps CI's run short.
TEST_CASE("40 start/end cycles leave no process, descriptor or listening port behind", "[manager][cycles][busy]") {
  check_start_end_cycles(40);
}

TEST_CASE("200 start/end cycles leave no process, descriptor or listening port behind", "[manager][cycles][flood]") {
  check_start_end_cycles(200);
}
