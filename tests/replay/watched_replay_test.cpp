// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb --replay, the study's video condition: a session A recorded by a real sim_rfb with a real client's
// keys is played by a second sim_rfb to a watcher B, started as sim_manager starts it (--ready-fd). B's picture
// at the recording's end matches sim_replay's video frame of A there, within the replay check's limits; B's own
// keys and pointer change nothing; B ends with "outcome watched" on the ready pipe; and A's folder is untouched.
// Once with A in the third-person view and once in the first-person one: B sees the view A had.
//
// Which tick a served picture shows: the stream does not say, so the picture compared is the last one. At the
// recording's end sim_rfb draws the end tick, then writes the outcome line, then holds the picture
// (--end-grace) while the watcher stays: a picture asked for after the line is the end's. A's walker released
// every key well before A ended, so the video's last frames show that same still moment.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "lossless_rfb_client.hpp"
#include "picture_compare.hpp"
#include "piped_sim.hpp"
#include "record/session_log.hpp"
#include "replay_fixtures.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "skip.hpp"

using namespace rfbsim;

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

// Every file of a folder with its bytes: the recording before and after it was watched.
std::map<std::string, std::string> folder_bytes(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    files[entry.path().lexically_relative(dir).string()] = bytes.str();
  }
  return files;
}

// Holds a key for `held`, pumping the connection meanwhile so that updates keep flowing.
void hold_key(test::RfbTestClient& client, std::uint32_t keysym, std::chrono::milliseconds held) {
  client.send_key(keysym, true);
  client.pump_until([] { return false; }, held);
  client.send_key(keysym, false);
}

// Records session A in `dir` with a real sim_rfb and a real client walking, turning, then standing still.
void record_walk(const std::filesystem::path& dir, const std::string& camera) {
  test::SimProcess sim(test::sim_rfb_path(), {"--port", "0", "--scenario", RFBSIM_STILL_SCENARIO, "--data-dir",
                                              dir.string(), "--width", std::to_string(kWidth), "--height",
                                              std::to_string(kHeight), "--uid", "p-walker", "--camera", camera});
  test::RfbTestClient client("127.0.0.1", sim.port());
  REQUIRE(client.wait_for_updates(1, std::chrono::seconds(20)));
  hold_key(client, 'w', std::chrono::milliseconds(1500));
  hold_key(client, 'a', std::chrono::milliseconds(800));
  // Standing still for a while before the end: the video's last frames and the end tick look alike.
  client.pump_until([] { return false; }, std::chrono::milliseconds(1000));
  const int status = sim.stop(SIGTERM);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
}

// The pose of the avatar in the last trajectory row.
const sim::TrajectoryRow& last_avatar(const sim::SessionLog& log) {
  return *std::find_if(log.trajectory.rbegin(), log.trajectory.rend(),
                       [](const sim::TrajectoryRow& r) { return r.kind == sim::AgentKind::Avatar; });
}

}  // namespace

TEST_CASE("sim_rfb --replay shows a recorded session to its end as sim_replay films it, ignores the watcher, ends watched",
          "[waits]") {
  if (std::string(RFBSIM_FFMPEG).empty()) RFBSIM_SKIP("ffmpeg not found at configure time (apt-get install ffmpeg)");
  // The watcher sees the view the walker had: the third-person camera, or the first-person one.
  const std::string camera = GENERATE(std::string("third_person"), std::string("first_person"));
  INFO("camera " << camera);
  const auto a_dir = test::fresh_dir("watched_a_" + camera);
  record_walk(a_dir, camera);
  const sim::SessionLog a = sim::read_session(a_dir);
  REQUIRE(sim::camera_mode_name(a.meta.camera) == camera);
  REQUIRE(a.meta.end_tick.has_value());
  REQUIRE(a.meta.tick_hz == 60);
  REQUIRE(a.meta.fps == 30);
  const sim::TrajectoryRow& start = a.trajectory.front();
  REQUIRE(start.kind == sim::AgentKind::Avatar);
  REQUIRE(std::hypot(last_avatar(a).x - start.x, last_avatar(a).y - start.y) > 0.5);  // the walk moved it
  const std::map<std::string, std::string> a_before = folder_bytes(a_dir);

  // sim_replay's video of A: frame k shows tick 2k; the last frame is the last even tick before the end.
  const auto video = a_dir.parent_path() / ("watched_a_" + camera + ".mp4");
  const test::ReplayRun filmed = test::run_replay({a_dir.string(), "--video", video.string(), "-q"});
  INFO(filmed.output);
  REQUIRE(filmed.exit_code == 0);
  const std::uint64_t last_frame = (*a.meta.end_tick - 1) / 2;
  const std::vector<test::Pixels> frames =
      test::decoded_frames(video, {0, last_frame}, kWidth, kHeight,
                           a_dir.parent_path() / ("watched_a_" + camera + ".rgb"));

  // B: the replay, as sim_manager would start it, with a watcher's data folder of its own.
  const auto b_dir = test::fresh_dir("watched_b_" + camera);
  test::PipedSim b(test::sim_rfb_path(),
                   {"--replay", a_dir.string(), "--port", "0", "--data-dir", b_dir.string(), "--uid", "w-watcher",
                    "--yoked-to", "7", "--end-grace", "600"},
                   {}, a_dir.parent_path() / ("watched_b_" + camera + ".log"));
  const std::string ready = b.await_line("ready ", std::chrono::seconds(60));
  REQUIRE(!ready.empty());
  const int port = std::stoi(ready.substr(6));
  // /status.json says it is a replay, and of what.
  const nlohmann::json status = nlohmann::json::parse(test::http_body(test::http_get(port, "/status.json")));
  REQUIRE(status.contains("replay"));
  CHECK(status["replay"]["uid"] == "p-walker");
  CHECK(status["replay"]["end_tick"] == *a.meta.end_tick);
  CHECK(status["replay"]["ended"] == false);

  {
    test::LosslessRfbClient watcher("127.0.0.1", port);
    test::RfbTestClient second("127.0.0.1", port);
    REQUIRE(watcher.width() == kWidth);
    REQUIRE(watcher.height() == kHeight);
    // B tries to walk the other way, turn and click; held down to the end.
    watcher.send_key('s', true);
    second.send_key('d', true);
    second.send_key(0xff52, true);  // Up: the camera
    second.send_pointer(10, 10, 1);
    REQUIRE(watcher.pump(std::chrono::milliseconds(200)));
    second.send_key('w', true);

    const std::string outcome = b.await_line("outcome ", std::chrono::seconds(120));
    CHECK(outcome == "outcome watched");

    // The end's picture: asked for after the line, and held until the watcher leaves. A picture asked for just
    // then may still be the one before; ask again until it has come (a deadline only for a broken server).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    test::Pixels shown;
    do {
      REQUIRE(watcher.refresh(std::chrono::seconds(10)));
      REQUIRE(watcher.pump(std::chrono::milliseconds(100)));
      shown = watcher.rgb();
    } while (!test::matches(shown, frames[1], test::kLossless) && std::chrono::steady_clock::now() < deadline);
    INFO("end picture against the video's last frame " << last_frame << ": MAD "
                                                       << test::mean_abs_difference(shown, frames[1]) << ", PSNR "
                                                       << test::psnr(shown, frames[1]) << " dB");
    CHECK(test::mean_abs_difference(shown, frames[1]) < test::kLossless.max_mad);
    CHECK(test::psnr(shown, frames[1]) > test::kLossless.min_psnr);
    // The comparison can fail: the start of A is another picture.
    CHECK_FALSE(test::matches(shown, frames[0], test::kLossless));
    const nlohmann::json ended = nlohmann::json::parse(test::http_body(test::http_get(port, "/status.json")));
    CHECK(ended["replay"]["ended"] == true);
    CHECK(ended["tick"] == *a.meta.end_tick);
    // B's keys moved nothing: the avatar stands where A's did at the end.
    CHECK(std::abs(ended["avatar"]["x"].get<double>() - last_avatar(a).x) < 1e-3);
    CHECK(std::abs(ended["avatar"]["y"].get<double>() - last_avatar(a).y) < 1e-3);
  }
  // The watchers left: the replay ends by itself (a signal now would be answered the same).
  const int exit_status = b.stop(SIGTERM);
  REQUIRE(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
  int outcome_lines = 0;
  for (const std::string& line : b.lines()) outcome_lines += line.rfind("outcome ", 0) == 0 ? 1 : 0;
  CHECK(outcome_lines == 1);

  // The watcher's record: a session.json of condition video naming what was replayed (by id and a hash of its
  // walker's uid, never the uid or its folder) and how it ended; no trajectories or inputs of its own.
  CHECK_FALSE(std::filesystem::exists(b_dir / "trajectories.csv"));
  CHECK_FALSE(std::filesystem::exists(b_dir / "events.jsonl"));
  std::ifstream watch_file(b_dir / "session.json");
  const std::string watch_text((std::istreambuf_iterator<char>(watch_file)), std::istreambuf_iterator<char>());
  const nlohmann::json watch = nlohmann::json::parse(watch_text);
  CHECK(watch["kind"] == "replay");
  CHECK(watch["condition"] == "video");
  CHECK(watch["uid"] == "w-watcher");
  CHECK(watch["yoked_to"] == 7);
  CHECK(watch["yoked_to_uid_hash"].get<std::string>().size() == 16);
  CHECK(watch["replay_of"]["uid_hash"] == watch["yoked_to_uid_hash"]);
  CHECK(watch["scenario"] == a.meta.scenario);
  CHECK(watch["camera"] == camera);
  CHECK(watch["outcome"] == "watched");
  CHECK(watch["end_reason"] == "watched");
  CHECK(watch["end_tick"] == *a.meta.end_tick);
  CHECK(watch["viewers"] == 2);
  CHECK(watch["ended_at"].is_string());
  CHECK(watch_text.find("p-walker") == std::string::npos);
  CHECK(watch_text.find(a_dir.filename().string()) == std::string::npos);

  // A is as it was: nothing written into the recording.
  CHECK(folder_bytes(a_dir) == a_before);
  std::filesystem::remove_all(a_dir);
  std::filesystem::remove_all(b_dir);
  std::filesystem::remove(video);
  std::filesystem::remove(a_dir.parent_path() / ("watched_a_" + camera + ".rgb"));
}
