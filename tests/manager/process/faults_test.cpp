// SPDX-License-Identifier: GPL-2.0-or-later
// Faults with real processes: a session killed with SIGKILL is marked crashed and its slot freed; a manager
// killed with SIGKILL leaves no session process behind, and its successor marks what it left interrupted;
// a browser that vanishes mid-stream costs nothing but its own connection.
#include <catch2/catch.hpp>

#include <csignal>
#include <sys/wait.h>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;

TEST_CASE("a session killed with SIGKILL is marked crashed and its slot is free at once", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--max-sessions", "1"}));
  const std::string token = token_from_redirect(manager.start("uid=crash-1"));
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  CHECK(manager.start("uid=crash-2").status == 503);  // full

  const auto killed_at = std::chrono::steady_clock::now();
  REQUIRE(::kill(static_cast<pid_t>(row->pid), SIGKILL) == 0);
  REQUIRE(manager.wait_for_state(token, "crashed", 10s));
  const auto marked_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - killed_at).count();
  // Measured, not asserted (shared machines): the manager hears SIGCHLD, so this is a few milliseconds.
  WARN("crashed session marked after " << marked_ms << " ms (the target is under 1000 ms)");
  const auto crashed = manager.row_for_token(token);
  REQUIRE(crashed);
  CHECK(crashed->exit_status == "signal 9");
  CHECK(crashed->detail.find("stopped by itself (signal 9)") != std::string::npos);
  // The slot is free: the next participant starts.
  CHECK(manager.start("uid=crash-2").status == 302);
  // The browser is told the simulator stopped.
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_close_code() == 1011);
  CHECK(bridge.last_close_reason() == "the simulator stopped unexpectedly");
  CHECK(manager.metric("rfbsim_sessions{state=\"crashed\"}") == 1);
  // A crash was not the participant's doing: the same link may start again (once the slot is free).
}

TEST_CASE("a manager killed with SIGKILL leaves no session behind, and its successor marks them interrupted",
          "[manager]") {
  TempDir data;
  std::vector<pid_t> session_pids;
  std::vector<std::string> tokens;
  {
    ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
    for (const char* uid : {"orphan-1", "orphan-2"}) {
      tokens.push_back(token_from_redirect(manager.start(std::string("uid=") + uid)));
      REQUIRE(manager.wait_for_state(tokens.back(), "running"));
      session_pids.push_back(static_cast<pid_t>(manager.row_for_token(tokens.back())->pid));
    }
    REQUIRE(manager.process().stop(SIGKILL) != -1);
  }
  // The sessions die with their manager (PR_SET_PDEATHSIG), not whenever someone notices.
  for (const pid_t pid : session_pids) {
    CHECK(rfbsim::test::eventually([pid] { return !rfbsim::test::process_exists(pid); }, 5s));
    CHECK_FALSE(rfbsim::test::group_has_running_member(pid));  // nor anything in their process groups
  }

  ManagerUnderTest successor(data.path(), rfbsim::test::small_session_args());
  const auto rows = successor.index_rows();
  REQUIRE(rows.size() == 2);
  for (const auto& row : rows) {
    CHECK(row.state == "interrupted");
    CHECK_FALSE(row.ended_at.empty());
    CHECK(row.detail == "the manager stopped unexpectedly while the session ran");
  }
  CHECK(successor.state_of(tokens[0]) == "interrupted");
  CHECK(successor.get("/s/" + tokens[0] + "/").status == 410);
  // An interrupted session was not the participant's doing: the same link starts afresh.
  const std::string again = token_from_redirect(successor.start("uid=orphan-1"));
  REQUIRE(again.size() == 32);
  CHECK(again != tokens[0]);
  CHECK(successor.wait_for_state(again, "running"));
}

TEST_CASE("a browser that vanishes mid-stream costs only its own connection", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  const std::string token = token_from_redirect(manager.start("uid=vanish-1"));
  REQUIRE(token.size() == 32);
  {
    auto bridge = std::make_unique<WsRfbBridge>(manager.ws_url(token));
    RfbTestClient client("127.0.0.1", bridge->port());
    REQUIRE(client.wait_for_updates(3, 20s));
    bridge.reset();  // drops the WebSocket without a close handshake, in the middle of the stream
  }
  REQUIRE(rfbsim::test::eventually(
      [&] { return manager.metric("rfbsim_relay_connections{kind=\"participant\"}") == 0; }, 10s));
  CHECK(manager.state_of(token) == "running");
  // The participant comes back and is served as before.
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(2, 20s));
  CHECK(manager.get("/healthz").status == 200);
}
