// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager as a real process with real sim_rfb sessions: a link starts a session and redirects at once,
// the first frame reaches a real RFB client (libvncclient) through the WebSocket relay, a refresh returns
// to the same session, two participants get two processes, a legacy RFB program can be served, a
// session that cannot start is marked failed, and stopping the manager ends every session.
#include <catch2/catch.hpp>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <sys/wait.h>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;

namespace {

// Whether a frame has a picture in it: not one flat colour.
bool has_picture(const rfbsim::FrameView& frame) {
  const std::uint8_t* first = frame.row(0);
  for (int y = 0; y < frame.height; y += 8) {
    const std::uint8_t* row = frame.row(y);
    for (int x = 0; x < frame.width; x += 8) {
      if (std::abs(int(row[x * 4]) - int(first[0])) + std::abs(int(row[x * 4 + 1]) - int(first[1])) > 30) return true;
    }
  }
  return false;
}

}  // namespace

TEST_CASE("a link starts a session, redirects at once, and the first frame arrives through the relay",
          "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::with_small_sessions({"--scenarios", "lab,warehouse"}));

  const auto response = manager.start("uid=p-01&scenario=lab&seed=42");
  REQUIRE(response.status == 302);
  const std::string token = rfbsim::test::token_from_redirect(response);
  REQUIRE(token.size() == 32);
  CHECK(response.headers.at("cache-control") == "no-store");

  // The participant page is served under the token, framed only by the manager itself.
  const auto page = manager.get("/s/" + token + "/");
  CHECK(page.status == 200);
  CHECK(page.body.find("app.bundle.js") != std::string::npos);
  CHECK(page.headers.at("content-security-policy") == "frame-ancestors 'self'");
  CHECK(page.headers.at("cache-control") == "no-store");
  CHECK(page.headers.at("referrer-policy") == "no-referrer");

  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  CHECK(client.width() == 320);
  CHECK(client.height() == 240);
  // The first update may carry only the desktop size; the picture follows at once (sim_rfb draws a frame
  // before it reports ready, so there is one to send).
  CHECK(client.pump_until([&] { return has_picture(client.frame()); }, 10s));
  CHECK(bridge.last().subprotocol == "binary");

  // The index has the session, running, with its process and folder.
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->uid == "p-01");
  CHECK(row->scenario == "lab");
  CHECK(row->seed == "42");
  CHECK(row->state == "running");
  CHECK(row->params == R"({"uid":"p-01","scenario":"lab","seed":"42"})");
  CHECK_FALSE(row->ready_at.empty());
  CHECK(rfbsim::test::process_exists(static_cast<pid_t>(row->pid)));
  CHECK(std::filesystem::is_regular_file(std::filesystem::path(row->data_path) / "session.log"));
  CHECK(manager.metric("rfbsim_relay_bytes_total{direction=\"to_client\"}") > 1000);
  CHECK(manager.metric("rfbsim_session_starts_total") == 1);
  CHECK(manager.metric("rfbsim_session_startup_seconds_count") == 1);

  SECTION("a refresh, or the link opened again, returns to the same session") {
    CHECK(rfbsim::test::token_from_redirect(manager.start("uid=p-01&scenario=lab&seed=42")) == token);
    CHECK(rfbsim::test::token_from_redirect(manager.start("uid=p-01")) == token);
    RfbTestClient second("127.0.0.1", bridge.port());
    CHECK(second.wait_for_updates(1, 20s));
    CHECK(manager.children().size() == 1);
    CHECK(manager.index_rows().size() == 1);
  }

  SECTION("two participants get two processes") {
    const std::string other = rfbsim::test::token_from_redirect(manager.start("uid=p-02&scenario=warehouse"));
    REQUIRE(other.size() == 32);
    CHECK(other != token);
    REQUIRE(manager.wait_for_state(other, "running"));
    const auto children = manager.children();
    CHECK(children.size() == 2);
    const auto rows = manager.index_rows();
    REQUIRE(rows.size() == 2);
    CHECK(rows[0].pid != rows[1].pid);
    CHECK(rows[1].scenario == "warehouse");
    WsRfbBridge other_bridge(manager.ws_url(other));
    RfbTestClient other_client("127.0.0.1", other_bridge.port());
    CHECK(other_client.wait_for_updates(1, 20s));
  }
}

TEST_CASE("a browser that connects while its session is starting is relayed once it is ready", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  // Connect in the same breath as the redirect: the session is (almost always) still starting.
  const std::string token = rfbsim::test::token_from_redirect(manager.start("uid=early&scenario=warehouse"));
  REQUIRE(token.size() == 32);
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(1, 20s));
}

TEST_CASE("a legacy program that serves raw RFB on a given port can be a session", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), {"--session-kind", "rfb", "--session-command", RFBSIM_MINIMAL,
                                         "--session-arg", "{port}", "--scenarios", "demo"});
  const std::string token = rfbsim::test::token_from_redirect(manager.start("uid=legacy-1"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  CHECK(client.width() == 640);  // rfbsim_minimal's size
  CHECK(client.height() == 480);
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->port > 0);
}

TEST_CASE("a session that cannot start is marked failed with the program's own words", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  // A goal off the map: sim_rfb refuses it before it listens and exits with 2.
  const std::string token =
      rfbsim::test::token_from_redirect(manager.start("uid=bad-goal&scenario=lab&robot_goal=500,500,0"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "failed"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->exit_status == "exit 2");
  CHECK(row->detail.find("scenario error") != std::string::npos);
  CHECK_FALSE(row->ended_at.empty());
  // The page says it has ended; the same link may try again (a failed start is not a completed session).
  CHECK(manager.get("/s/" + token + "/").status == 410);
  CHECK(manager.start("uid=bad-goal&scenario=lab&robot_goal=500,500,0").status == 302);
}

TEST_CASE("stopping the manager ends every session it started", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  const std::string a = rfbsim::test::token_from_redirect(manager.start("uid=s-1"));
  const std::string b = rfbsim::test::token_from_redirect(manager.start("uid=s-2"));
  REQUIRE(manager.wait_for_state(a, "running"));
  REQUIRE(manager.wait_for_state(b, "running"));
  const auto before = manager.index_rows();
  WsRfbBridge bridge(manager.ws_url(a));
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));

  const int status = manager.process().stop(SIGTERM, 20s);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  for (const auto& row : before) CHECK_FALSE(rfbsim::test::process_exists(static_cast<pid_t>(row.pid)));
  for (const auto& row : manager.index_rows()) {
    CHECK(row.state == "shutdown");
    CHECK_FALSE(row.ended_at.empty());
  }
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_close_code() == 1001);
  CHECK(bridge.last_close_reason() == "server shutting down");
}
