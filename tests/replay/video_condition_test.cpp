// SPDX-License-Identifier: GPL-2.0-or-later
// The study's video condition through sim_manager (issue 33), as a study runs it: walker A's link, A walks
// with scripted keys through the manager's relay, the researcher ends A (POST /api/sessions/<id>/end); then two
// video links of A's scenario arrive at once. One gets A's session (302), the other a 503 that tells its survey
// "unavailable": A may be watched once (yoke_max_viewers 1), and the choice is atomic. Watcher B's picture
// changes with no key pressed, B's own keys change nothing, B's last picture is sim_replay's last frame of A
// within the replay check's limits, and B ends "watched" with the video link's own code. The records name the
// condition and the source by id and uid hash, never A's uid; A's row counts its watcher.
//
// The still lab (no crowd, no robot, no task) makes the picture change only when A's avatar moves, so that B's
// end picture and the video's last frame show the same still moment (see watched_replay_test.cpp).
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <future>
#include <sstream>

#include <nlohmann/json.hpp>

#include "lossless_rfb_client.hpp"
#include "manager_process.hpp"
#include "picture_compare.hpp"
#include "record/digest.hpp"
#include "record/session_log.hpp"
#include "replay_fixtures.hpp"
#include "rfb_test_client.hpp"
#include "skip.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using nlohmann::json;
using namespace rfbsim;

namespace {

constexpr int kWatchWidth = 320;
constexpr int kWatchHeight = 240;
constexpr const char* kKey = "video-condition-test-key";

std::string file_text_of(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

json api_sessions_json(const test::ManagerUnderTest& manager) {
  const auto response =
      manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + test::kAdminToken}});
  REQUIRE(response.status == 200);
  return json::parse(response.body);
}

// The /api/sessions entry (live or recent) of session `id`.
json api_entry(const test::ManagerUnderTest& manager, std::int64_t id) {
  const json all = api_sessions_json(manager);
  for (const char* list : {"live", "recent"}) {
    for (const json& entry : all[list]) {
      if (entry["id"] == id) return entry;
    }
  }
  FAIL("session " << id << " is not in /api/sessions");
  return {};
}

}  // namespace

TEST_CASE("a video link shows a watcher the walker's ended session through sim_manager, once, view-only, to its end",
          "[waits]") {
  if (std::string(RFBSIM_FFMPEG).empty()) RFBSIM_SKIP("ffmpeg not found at configure time (apt-get install ffmpeg)");
  test::TempDir data;
  ::setenv("RFBSIM_ADDRESS_KEY", kKey, 1);  // inherited by the manager and its sessions
  test::ManagerUnderTest manager(
      data.path(), {"--admin-token", test::kAdminToken, "--scenarios", std::string("still=") + RFBSIM_STILL_SCENARIO,
                    "--session-arg", "--end-grace", "--session-arg", "30", "--session-arg", "--width", "--session-arg", std::to_string(kWatchWidth), "--session-arg", "--height",
                    "--session-arg", std::to_string(kWatchHeight)});
  ::unsetenv("RFBSIM_ADDRESS_KEY");

  // Nothing to watch yet: a 503 whose page tells a framing survey "unavailable".
  const auto early = manager.start("uid=vid-early&scenario=still&condition=video");
  CHECK(early.status == 503);
  CHECK(early.body.find("No recording to watch right now") != std::string::npos);
  CHECK(early.body.find("outcome: 'unavailable'") != std::string::npos);

  // Bad video links: a clear 400, and the manager serves on.
  const auto bad_condition = manager.start("uid=vid-bad&scenario=still&condition=watch");
  CHECK(bad_condition.status == 400);
  CHECK(bad_condition.body.find("use interactive or video") != std::string::npos);
  const auto seeded = manager.start("uid=vid-bad&scenario=still&condition=video&seed=3");
  CHECK(seeded.status == 400);
  CHECK(seeded.body.find("seed is not valid with condition=video") != std::string::npos);
  CHECK(manager.start("uid=vid-bad&scenario=still&yoke_uid=vid-a").status == 400);

  // A walks: forward, a turn, then stands still, through the manager's relay.
  const std::string a_token = test::token_from_redirect(manager.start("uid=vid-a&scenario=still"));
  REQUIRE(a_token.size() == 32);
  REQUIRE(manager.wait_for_state(a_token, "running"));
  {
    test::WsRfbBridge bridge(manager.ws_url(a_token));
    test::RfbTestClient walker("127.0.0.1", bridge.port());
    REQUIRE(walker.wait_for_updates(1, 20s));
    walker.send_key('w', true);
    walker.pump_until([] { return false; }, 2000ms);
    walker.send_key('w', false);
    walker.send_key('a', true);
    walker.pump_until([] { return false; }, 600ms);
    walker.send_key('a', false);
    walker.pump_until([] { return false; }, 1500ms);
  }
  const auto a_row = manager.row_for_token(a_token);
  REQUIRE(a_row);
  const auto ended = manager.end_session(a_row->id, test::kAdminToken);
  REQUIRE(ended.status == 200);
  REQUIRE(manager.wait_for_state(a_token, "ended", 30s));
  const std::filesystem::path a_dir = a_row->data_path;
  const sim::SessionLog a = sim::read_session(a_dir);
  REQUIRE(a.meta.end_tick.has_value());

  // sim_replay's video of A; its last frame is the still moment A ended in.
  const auto video = data.path() / "a.mp4";
  const test::ReplayRun filmed = test::run_replay({a_dir.string(), "--video", video.string(), "-q"});
  INFO(filmed.output);
  REQUIRE(filmed.exit_code == 0);
  const std::uint64_t ticks_per_frame = static_cast<std::uint64_t>(a.meta.tick_hz / a.meta.fps);
  const std::uint64_t last_frame = (*a.meta.end_tick - 1) / ticks_per_frame;
  const std::vector<test::Pixels> frames =
      test::decoded_frames(video, {0, last_frame}, kWatchWidth, kWatchHeight, data.path() / "a.rgb");

  // Two watchers at once: exactly one gets A's session.
  auto first = std::async(std::launch::async, [&] { return manager.start("uid=vid-b&scenario=still&condition=video"); });
  auto second = std::async(std::launch::async, [&] { return manager.start("uid=vid-c&scenario=still&condition=video"); });
  const auto b_answer = first.get();
  const auto c_answer = second.get();
  CHECK(b_answer.status + c_answer.status == 302 + 503);
  const bool b_won = b_answer.status == 302;
  const std::string b_uid = b_won ? "vid-b" : "vid-c";
  const std::string b_token = test::token_from_redirect(b_won ? b_answer : c_answer);
  REQUIRE(b_token.size() == 32);
  const auto& refused = b_won ? c_answer : b_answer;
  CHECK(refused.body.find("No recording to watch right now") != std::string::npos);
  // Asked again, still none: A has its one watcher.
  CHECK(manager.start("uid=vid-d&scenario=still&condition=video").status == 503);
  REQUIRE(manager.wait_for_state(b_token, "running"));

  const auto b_row = manager.row_for_token(b_token);
  REQUIRE(b_row);
  const json b_api = api_entry(manager, b_row->id);
  CHECK(b_api["condition"] == "video");
  CHECK(b_api["yoked_to"] == a_row->id);
  CHECK(b_api["yoked_to_uid_hash"] == sim::hash_uid(kKey, "vid-a"));
  CHECK(b_api["seed"] == a_row->seed);
  CHECK(b_api["params"]["condition"] == "video");
  CHECK(json::parse(manager.get("/s/" + b_token + "/status").body)["condition"] == "video");

  {
    test::WsRfbBridge bridge(manager.ws_url(b_token));
    test::LosslessRfbClient watcher("127.0.0.1", bridge.port());
    REQUIRE(watcher.width() == kWatchWidth);
    REQUIRE(watcher.refresh(20s));
    const test::Pixels at_start = watcher.rgb();
    // B presses keys all along; they must change nothing.
    watcher.send_key('s', true);
    watcher.send_key('d', true);
    // The picture changes with the replay alone: A walked in the first seconds.
    bool changed = false;
    for (int i = 0; i < 40 && !changed; ++i) {
      REQUIRE(watcher.pump(250ms));
      changed = !test::matches(watcher.rgb(), at_start, test::kLossless);
    }
    CHECK(changed);
    REQUIRE(test::eventually(
        [&] {
          if (!watcher.pump(100ms)) FAIL("the watcher's connection failed while the replay played");
          return json::parse(manager.get("/s/" + b_token + "/status").body)["outcome"] == "watched";
        },
        60s));
    // The end's picture: asked for after the outcome, held while the watcher stays (the study's --end-grace;
    // without one 3 s, or 15 s with a code to show, which the picture then shows as well).
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    test::Pixels shown;
    do {
      if (!watcher.refresh(10s)) FAIL("no picture after the outcome; B's log:\n" << file_text_of(std::filesystem::path(b_row->data_path) / "session.log"));
      shown = watcher.rgb();
    } while (!test::matches(shown, frames[1], test::kLossless) && std::chrono::steady_clock::now() < deadline);
    INFO("B's end picture against the video's last frame " << last_frame << ": MAD "
                                                           << test::mean_abs_difference(shown, frames[1]) << ", PSNR "
                                                           << test::psnr(shown, frames[1]) << " dB");
    CHECK(test::matches(shown, frames[1], test::kLossless));
    CHECK_FALSE(test::matches(shown, frames[0], test::kLossless));  // the comparison can fail
  }
  REQUIRE(manager.wait_for_state(b_token, "finished", 40s));

  // The records: B's index row, manager.json and session.json; A's row counts B.
  const std::filesystem::path b_dir = b_row->data_path;
  const json b_manager = json::parse(file_text_of(b_dir / "manager.json"));
  CHECK(b_manager["condition"] == "video");
  CHECK(b_manager["yoked_to"] == a_row->id);
  CHECK(b_manager["outcome"] == "watched");
  const std::string b_session_text = file_text_of(b_dir / "session.json");
  const json b_session = json::parse(b_session_text);
  CHECK(b_session["condition"] == "video");
  CHECK(b_session["yoked_to"] == a_row->id);
  CHECK(b_session["uid"] == b_uid);
  CHECK(b_session["outcome"] == "watched");
  // B's keys reached nothing: a watcher's folder has no inputs or trajectories of its own.
  CHECK_FALSE(std::filesystem::exists(b_dir / "events.jsonl"));
  CHECK_FALSE(std::filesystem::exists(b_dir / "trajectories.csv"));
  for (const std::string& text : {b_session_text, file_text_of(b_dir / "manager.json"), file_text_of(b_dir / "session.log")}) {
    CHECK(text.find("vid-a") == std::string::npos);  // never A's uid
  }
  CHECK(api_entry(manager, a_row->id)["watchers"] == 1);
  CHECK(api_entry(manager, a_row->id)["condition"] == "interactive");
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"no_recording\"}") >= 3);

  // sim_report on the study's data folder: the condition columns, and the pair (A, B) ready for paired tests.
  const auto report_dir = data.path() / "report-out";
  const test::ExitResult reported =
      test::run_to_exit(RFBSIM_SIM_REPORT, {data.path().string(), "--out", report_dir.string()}, 60s);
  INFO(reported.output);
  REQUIRE(WIFEXITED(reported.status));
  CHECK(WEXITSTATUS(reported.status) == 0);
  const std::string sessions_csv = file_text_of(report_dir / "sessions.csv");
  CHECK(sessions_csv.substr(0, sessions_csv.find('\n')).find(",condition,yoked_to,") != std::string::npos);
  const std::string pairs_csv = file_text_of(report_dir / "pairs.csv");
  std::istringstream pair_lines(pairs_csv);
  std::string header, row, extra;
  std::getline(pair_lines, header);
  REQUIRE(std::getline(pair_lines, row));
  CHECK_FALSE(std::getline(pair_lines, extra));  // one pair
  CHECK(header.rfind("pair,host,scenario,source_session,source_uid,", 0) == 0);
  CHECK(row.find("," + std::to_string(a_row->id) + ",vid-a,") != std::string::npos);
  CHECK(row.find("," + std::to_string(b_row->id) + "," + b_uid + ",") != std::string::npos);
  CHECK(reported.output.find("1 video-condition pair") != std::string::npos);
}
