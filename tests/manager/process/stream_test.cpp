// SPDX-License-Identifier: GPL-2.0-or-later
// The participant's picture stream as sim_manager shows it: sim_rfb's stream lines on the ready pipe reach the
// admin API and the metrics while a client watches through the relay, and go away when it leaves; the configured
// codec reaches sim_rfb's command line.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "manager_process.hpp"
#include "h264_rfb_client.hpp"
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


// The live session of `token` as /api/sessions shows it (null when it is not listed or the API fails).
nlohmann::json live_session(const ManagerUnderTest& manager, const std::string& token) {
  const auto response = manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + kAdminToken}});
  if (response.status != 200) return nullptr;
  const auto body = nlohmann::json::parse(response.body, nullptr, false);
  if (body.is_discarded() || !body.contains("live")) return nullptr;
  for (const auto& session : body["live"]) {
    if (session.value("token", "") == token) return session;
  }
  return nullptr;
}

// Pumps `client` (if any) and polls the API until `done(session)` holds for `token`'s live session, or 20 s pass.
template <typename Done>
bool await_session(const ManagerUnderTest& manager, const std::string& token, RfbTestClient* client, Done done,
                   nlohmann::json& session) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline) {
    session = live_session(manager, token);
    if (!session.is_null() && done(session)) return true;
    if (client != nullptr) {
      client->pump_until([] { return false; }, 100ms);
    } else {
      std::this_thread::sleep_for(100ms);
    }
  }
  return false;
}

// The arguments process `pid` was started with (from /proc), without the program name.
std::vector<std::string> command_line(std::int64_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::ostringstream read;
  read << file.rdbuf();
  const std::string text = read.str();
  std::vector<std::string> args;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = text.find('\0', start);
    args.push_back(text.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (!args.empty()) args.erase(args.begin());
  return args;
}

}  // namespace

TEST_CASE("a session's stream reaches the admin API and the metrics while a client watches through the relay",
          "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--scenarios", "lab", "--admin-token", kAdminToken}));
  const std::string token = token_from_redirect(manager.start("uid=stream-1&scenario=lab"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));

  // Nobody watches yet: nothing is known of a stream.
  nlohmann::json session = live_session(manager, token);
  REQUIRE(session.is_object());
  CHECK(session["codec"].is_null());
  CHECK(session["rtt_ms"].is_null());
  CHECK(session["fps"].is_null());
  const std::string label = "{session=\"" + std::to_string(session["id"].get<std::int64_t>()) + "\"";
  CHECK(manager.metric("rfbsim_session_fps" + label + "}") == -1);

  {
    // A libvncclient client through the relay, walking so that the picture keeps changing.
    WsRfbBridge bridge(manager.ws_url(token));
    RfbTestClient client("127.0.0.1", bridge.port());
    REQUIRE(client.wait_for_updates(1, 20s));
    client.send_key('w', true);
    REQUIRE(await_session(manager, token, &client, [](const nlohmann::json& s) {
      return s["codec"] == "tight" && s["fps"].is_number() && s["fps"].get<double>() > 0;
    }, session));
    INFO(session.dump());
    // libvncclient answers no fences, so the round trip is not measured.
    CHECK(session["rtt_ms"].is_null());
    CHECK(manager.metric("rfbsim_session_fps" + label + "}") > 0);
    CHECK(manager.metric("rfbsim_session_codec_info" + label + ",codec=\"tight\"}") == 1);
    CHECK(manager.metric("rfbsim_session_rtt_ms" + label + "}") == -1);
    // Tight's JPEG quality, as sim_rfb reported it.
    REQUIRE(session["quality"].is_number_integer());
    CHECK(session["quality"].get<int>() >= 1);
    CHECK(session["quality"].get<int>() <= 100);
    CHECK(manager.metric("rfbsim_session_quality" + label + "}") == session["quality"].get<int>());
    client.send_key('w', false);
  }

  // The client left: sim_rfb says nobody watches, and the stream is no longer shown.
  REQUIRE(await_session(manager, token, nullptr, [](const nlohmann::json& s) { return s["codec"].is_null(); },
                        session));
  CHECK(session["fps"].is_null());
  CHECK(session["quality"].is_null());
  CHECK(manager.metric("rfbsim_session_quality" + label + "}") == -1);
  CHECK(manager.metric("rfbsim_session_codec_info" + label + ",codec=\"tight\"}") == -1);
}

TEST_CASE("the configured codec reaches sim_rfb's command line", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--scenarios", "lab", "--codec", "h264"}));
  const std::string token = token_from_redirect(manager.start("uid=codec-1&scenario=lab"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const std::vector<std::string> args = command_line(row->pid);
  std::string joined;
  for (const std::string& arg : args) joined += arg + " ";
  INFO(joined);
  const auto codec = std::find(args.begin(), args.end(), "--codec");
  REQUIRE(codec != args.end());
  REQUIRE(codec + 1 != args.end());
  CHECK(*(codec + 1) == "h264");
  // sim_rfb says so in the session's log.
  CHECK(rfbsim::test::eventually([&] {
    std::ifstream log(row->data_path + "/session.log");
    std::ostringstream text;
    text << log.rdbuf();
    return text.str().find("[sim_rfb] picture encoding h264") != std::string::npos;
  }, 10s));
  // sim_rfb took it: the session runs and serves a client (Tight for libvncclient, which offers no H.264).
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(1, 20s));
}

TEST_CASE("ContinuousUpdates and fences pass the relay unchanged, and the round trip is measured through it",
          "[manager][streaming]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--scenarios", "lab", "--admin-token", kAdminToken,
                                                             "--codec", "jpeg"}));
  const std::string token = token_from_redirect(manager.start("uid=stream-cu&scenario=lab"));
  REQUIRE(manager.wait_for_state(token, "running"));
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port(), 8, rfbsim::test::UpdateMode::kContinuous);
  REQUIRE(client.pump_until([&] { return client.continuous(); }, 20s));
  client.send_key('d', true);  // turning: the picture keeps changing
  const std::uint64_t before = client.updates();
  // No request is sent from here on: every update is pushed through the relay, each followed by a ping.
  CHECK(client.wait_for_updates(20, 30s));
  CHECK(client.updates() >= before + 20);
  CHECK(client.fences_answered() >= 20);
  CHECK(client.bad_fences() == 0);
  CHECK(client.end_of_continuous_updates() == 1);
  nlohmann::json session;
  REQUIRE(await_session(manager, token, &client, [](const nlohmann::json& s) {
    return s["codec"] == "tight" && s["rtt_ms"].is_number();
  }, session));
  INFO(session.dump());
  CHECK(session["rtt_ms"].get<double>() >= 0.0);
  client.send_key('d', false);
}

TEST_CASE("H.264 pictures pass the relay and decode", "[manager][streaming]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--scenarios", "lab", "--admin-token", kAdminToken,
                                                             "--codec", "h264"}));
  const std::string token = token_from_redirect(manager.start("uid=stream-h264&scenario=lab"));
  REQUIRE(manager.wait_for_state(token, "running"));
  WsRfbBridge bridge(manager.ws_url(token));
  rfbsim::test::H264RfbClient client("127.0.0.1", bridge.port());
  client.send_key('d', true);
  CHECK(client.wait_for_updates(10, 30s));
  CHECK(client.h264_pictures() >= 10);
  CHECK(client.idr_pictures() >= 1);
  CHECK(client.decode_errors() == 0);
  CHECK(client.continuous());
  nlohmann::json session;
  REQUIRE(await_session(manager, token, nullptr, [&](const nlohmann::json& s) {
    client.pump_until([] { return false; }, 100ms);
    return s["codec"] == "h264";
  }, session));
  client.send_key('d', false);
}
