// SPDX-License-Identifier: GPL-2.0-or-later
// How sessions are shown: close notices per state, the page's status poll and the admin API's JSON.
#include <catch2/catch.hpp>

#include "sessions/session_index.hpp"
#include "admin/admin_api.hpp"
#include "sessions/session_views.hpp"

using rfbsim::manager::close_notice;
using rfbsim::manager::coming_state;
using rfbsim::manager::Session;
using rfbsim::manager::SessionState;

namespace {

Session sample() {
  Session s;
  s.id = 7;
  s.uid = "p-01";
  s.token = "0123456789abcdef0123456789abcdef";
  s.scenario = "lab";
  s.params_json = R"({"uid":"p-01","scenario":"lab","seed":"42"})";
  s.seed = 42;
  s.state = SessionState::kRunning;
  s.data_path = "/data/sessions/7-p-01";
  s.created = *rfbsim::manager::parse_iso_utc("2026-11-24T10:00:00.000Z");
  s.ready_at = rfbsim::manager::parse_iso_utc("2026-11-24T10:00:00.250Z");
  return s;
}

}  // namespace

TEST_CASE("each ending tells the browser its own close code and reason") {
  CHECK(close_notice(SessionState::kFinished).code == 1000);
  CHECK(close_notice(SessionState::kFinished).reason == "session finished");
  CHECK(close_notice(SessionState::kExpired).code == 1001);
  CHECK(close_notice(SessionState::kExpired).reason == "session expired");
  CHECK(close_notice(SessionState::kIdle).reason == "session ended after being idle");
  CHECK(close_notice(SessionState::kEnded).reason == "session ended by the researcher");
  CHECK(close_notice(SessionState::kShutdown).code == 1001);
  CHECK(close_notice(SessionState::kShutdown).reason == "server shutting down");
  CHECK(close_notice(SessionState::kFailed).code == 1011);
  CHECK(close_notice(SessionState::kFailed).reason == "the simulator could not start");
  CHECK(close_notice(SessionState::kCrashed).code == 1011);
  CHECK(close_notice(SessionState::kCrashed).reason == "the simulator stopped unexpectedly");
}

TEST_CASE("an ending session is shown as the state it is ending into") {
  Session s = sample();
  CHECK(coming_state(s) == SessionState::kRunning);
  REQUIRE(rfbsim::manager::begin_ending(s, SessionState::kExpired, "time"));
  CHECK(s.state == SessionState::kEnding);
  CHECK(coming_state(s) == SessionState::kExpired);
}

TEST_CASE("the status poll gives the state, what it ends as, and the seconds since the link") {
  Session s = sample();
  const auto now = s.created + std::chrono::milliseconds(1500);
  CHECK(rfbsim::manager::status_json(s, now, {}) ==
        R"({"state":"running","ends_as":"running","elapsed_s":1.500,"uid":"p-01","outcome":null,"code":null,)"
        R"("survey_origins":[]})");
  REQUIRE(rfbsim::manager::begin_ending(s, SessionState::kEnded, "admin"));
  CHECK(rfbsim::manager::status_json(s, now, {}) ==
        R"({"state":"ending","ends_as":"ended","elapsed_s":1.500,"uid":"p-01","outcome":null,"code":null,)"
        R"("survey_origins":[]})");
}

TEST_CASE("the status poll names another program than sim_rfb, so that the page drops the WASD hint") {
  Session s = sample();
  const auto now = s.created + std::chrono::milliseconds(1500);
  CHECK(rfbsim::manager::status_json(s, now, {}, "x11") ==
        R"({"state":"running","ends_as":"running","elapsed_s":1.500,"uid":"p-01","outcome":null,"code":null,)"
        R"("survey_origins":[],"program":"x11"})");
  CHECK(rfbsim::manager::status_json(s, now, {}, "sim_rfb").find("program") == std::string::npos);
}

TEST_CASE("the status poll gives the outcome with the code the link carried for it, and the survey origins") {
  Session s = sample();
  s.code_success = "DONE-1";
  s.code_timeout = "LATE-2";
  const auto now = s.created + std::chrono::milliseconds(1500);
  const std::vector<std::string> origins = {"https://survey.example", "https://x.example"};
  s.outcome = "completed";
  CHECK(rfbsim::manager::status_json(s, now, origins) ==
        R"({"state":"running","ends_as":"running","elapsed_s":1.500,"uid":"p-01","outcome":"completed",)"
        R"("code":"DONE-1","survey_origins":["https://survey.example","https://x.example"]})");
  s.outcome = "timeout";
  CHECK(rfbsim::manager::status_json(s, now, {}).find(R"("outcome":"timeout","code":"LATE-2")") != std::string::npos);
  s.code_timeout.clear();
  CHECK(rfbsim::manager::status_json(s, now, {}).find(R"("outcome":"timeout","code":null)") != std::string::npos);
}

TEST_CASE("a replay's watcher (outcome watched) is given the success code, as a completed session is for now") {
  Session s = sample();
  s.code_success = "DONE-1";
  s.code_timeout = "LATE-2";
  s.outcome = "watched";
  const auto now = s.created + std::chrono::milliseconds(1500);
  CHECK(rfbsim::manager::status_json(s, now, {}).find(R"("outcome":"watched","code":"DONE-1")") != std::string::npos);
  s.code_success.clear();
  CHECK(rfbsim::manager::status_json(s, now, {}).find(R"("outcome":"watched","code":null)") != std::string::npos);
}

TEST_CASE("the admin API's session JSON names every field, and the token only when asked") {
  Session s = sample();
  s.detail = "said \"hi\"";
  const std::string expected =
      R"({"id":7,"uid":"p-01","scenario":"lab","seed":"42","state":"running","detail":"said \"hi\"",)"
      R"("exit_status":"","created_at":"2026-11-24T10:00:00.000Z","ready_at":"2026-11-24T10:00:00.250Z",)"
      R"("ended_at":null,"data_path":"/data/sessions/7-p-01","outcome":null,)"
      R"("copy_state":"","copy_attempts":0,"copy_error":"",)"
      R"("params":{"uid":"p-01","scenario":"lab","seed":"42"},"ros_namespace":null,"robot_control":null,)"
      R"("condition":"interactive","yoked_to":null,"yoked_to_uid_hash":null,"watchers":0,)"
      R"("codec":null,"rtt_ms":null,"fps":null,"quality":null)";
  CHECK(rfbsim::manager::admin_session_json(s, false) == expected + "}");
  CHECK(rfbsim::manager::admin_session_json(s, true) == expected + R"(,"token":"0123456789abcdef0123456789abcdef"})");
}

TEST_CASE("the admin API's session JSON carries the participant's stream while someone watches") {
  Session s = sample();
  const auto stream_part = [&] {
    const std::string json = rfbsim::manager::admin_session_json(s, false);
    return json.substr(json.find(R"("codec")"));
  };
  CHECK(stream_part() == R"("codec":null,"rtt_ms":null,"fps":null,"quality":null})");
  s.stream = rfbsim::manager::StreamReport{1, "h264", 52.34, 29.66, 80, std::nullopt};
  CHECK(stream_part() == R"("codec":"h264","rtt_ms":52.3,"fps":29.7,"quality":80})");
  // A stream without a measured round trip (a client without fences) says so with null.
  s.stream->rtt_ms.reset();
  s.stream->codec = "tight";
  CHECK(stream_part() == R"("codec":"tight","rtt_ms":null,"fps":29.7,"quality":80})");
  // A lossless encoding has no quality.
  s.stream->codec = "zrle";
  s.stream->quality.reset();
  CHECK(stream_part() == R"("codec":"zrle","rtt_ms":null,"fps":29.7,"quality":null})");
  // Nobody watching: nothing to show, whatever was reported before.
  s.stream->quality = 80;
  s.stream->clients = 0;
  CHECK(stream_part() == R"("codec":null,"rtt_ms":null,"fps":null,"quality":null})");
}

TEST_CASE("the session record beside the data says how the session ended, with no token") {
  rfbsim::manager::Session session;
  session.id = 7;
  session.uid = "p\"1";
  session.token = "0123456789abcdef0123456789abcdef";
  session.state = rfbsim::manager::SessionState::kAbandoned;
  session.detail = "no browser connected for 60 s";
  session.host_id = "h2";
  session.created = rfbsim::manager::WallTime{} + std::chrono::seconds(1'700'000'000);
  session.ended_at = session.created + std::chrono::seconds(61);
  CHECK(rfbsim::manager::session_record_json(session) ==
        "{\"id\":7,\"uid\":\"p\\\"1\",\"host\":\"h2\",\"address_hash\":null,\"state\":\"abandoned\","
        "\"detail\":\"no browser connected for 60 s\","
        "\"created_at\":\"2023-11-14T22:13:20.000Z\",\"ready_at\":null,\"spent_at\":null,"
        "\"ended_at\":\"2023-11-14T22:14:21.000Z\",\"outcome\":null,\"data_incomplete\":null,"
        "\"ros_namespace\":null,\"robot_control\":null,\"condition\":\"interactive\",\"yoked_to\":null,"
        "\"yoked_to_uid_hash\":null}\n");
  session.spent_at = session.created + std::chrono::milliseconds(1500);
  session.data_incomplete = "events.jsonl: cannot write (No space left on device)";
  session.address_hash = "0123456789abcdef";
  const std::string with = rfbsim::manager::session_record_json(session);
  CHECK(with.find("\"spent_at\":\"2023-11-14T22:13:21.500Z\"") != std::string::npos);
  CHECK(with.find("\"data_incomplete\":\"events.jsonl: cannot write (No space left on device)\"") != std::string::npos);
  CHECK(with.find("\"host\":\"h2\",\"address_hash\":\"0123456789abcdef\",") != std::string::npos);
  CHECK(with.find(session.token) == std::string::npos);
}

TEST_CASE("the researcher sees a session's ROS namespace and robot control, the participant's poll does not") {
  Session s = sample();
  s.ros_namespace = "/rfbsim/s_7";
  s.robot_control = "external";
  const std::string admin = rfbsim::manager::admin_session_json(s, false);
  CHECK(admin.find(R"("ros_namespace":"/rfbsim/s_7","robot_control":"external",)") != std::string::npos);
  CHECK(rfbsim::manager::session_record_json(s).find(R"("ros_namespace":"/rfbsim/s_7","robot_control":"external",)") !=
        std::string::npos);
  // The participant's page is told nothing of the lab's ROS.
  const std::string status = rfbsim::manager::status_json(s, s.created, {});
  CHECK(status.find("ros") == std::string::npos);
  CHECK(status.find("robot") == std::string::npos);
  CHECK(status.find("rfbsim/s_7") == std::string::npos);
  // A robot driven by the simulator, no ROS.
  s.ros_namespace.clear();
  s.robot_control = "builtin";
  CHECK(rfbsim::manager::admin_session_json(s, false).find(R"("ros_namespace":null,"robot_control":"builtin",)") !=
        std::string::npos);
}

TEST_CASE("a watcher's session names the session it was shown by id and uid hash, never by uid") {
  Session watcher = sample();
  watcher.condition = "video";
  watcher.yoked_to = 3;
  watcher.yoked_to_uid_hash = "00112233aabbccdd";
  const std::string admin = rfbsim::manager::admin_session_json(watcher, false);
  CHECK(admin.find(R"("condition":"video","yoked_to":3,"yoked_to_uid_hash":"00112233aabbccdd","watchers":0,)") !=
        std::string::npos);
  CHECK(rfbsim::manager::session_record_json(watcher).find(
            R"("condition":"video","yoked_to":3,"yoked_to_uid_hash":"00112233aabbccdd"})") != std::string::npos);
  // The page learns that its participant watches (and drops the keyboard hint); an interactive poll is as it was.
  CHECK(rfbsim::manager::status_json(watcher, watcher.created, {}).find(R"(,"condition":"video"})") !=
        std::string::npos);
  CHECK(rfbsim::manager::status_json(sample(), watcher.created, {}).find("condition") == std::string::npos);
  // The source counts its watchers for the researcher.
  Session source = sample();
  source.watchers = 2;
  CHECK(rfbsim::manager::admin_session_json(source, false).find(R"("yoked_to":null,"yoked_to_uid_hash":null,"watchers":2,)") !=
        std::string::npos);
}
