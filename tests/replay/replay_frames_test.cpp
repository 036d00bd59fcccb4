// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's video shows what sim_rfb served: a real sim_rfb, a real participant pressing keys over RFB,
// pictures captured from the live stream at known ticks, the session replayed into a video, and the video's
// frames at those ticks compared with the captured ones.
//
// Which tick a served picture shows: sim_rfb draws after its steps at the frame rate, at whatever tick the
// wall clock reached, and the stream does not say which. So pictures are taken only while the world is still
// (tests/replay/scenarios/still_lab.yaml: the tutorial's lab without robot, pedestrians or a task clock on
// the HUD; keys released). /status.json
// gives the tick and the count of frames rendered; sim_rfb renders a frame only when it would look different
// from the last one (FramePainter), so an unchanged count across a span of ticks says every tick of that span
// looks as the picture served, and any one of them names it. No hook in sim_rfb is needed.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <iterator>
#include <limits>

#include "lossless_rfb_client.hpp"
#include "picture_compare.hpp"
#include "record/session_log.hpp"
#include "replay_fixtures.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "skip.hpp"

using namespace rfbsim;

namespace {

using test::kJpeg;
using test::kLossless;
using test::mean_abs_difference;
using test::Pixels;
using test::psnr;
using test::rgb_of;

constexpr int kWidth = 320;
constexpr int kHeight = 240;

// What sim_rfb's /status.json says now: the tick and how many frames it has rendered.
struct SimStatus {
  std::uint64_t tick = 0;
  std::uint64_t frames = 0;
};

SimStatus status_of(int port) {
  const std::string body = test::http_body(test::http_get(port, "/status.json"));
  const double tick = test::json_number(body, "tick");
  const double frames = test::json_number(body, "frames_rendered");
  INFO(body);
  REQUIRE(std::isfinite(tick));
  REQUIRE(std::isfinite(frames));
  return {static_cast<std::uint64_t>(tick), static_cast<std::uint64_t>(frames)};
}

// One still moment of the live session: the ticks it held over, and the picture both viewers had.
struct Still {
  std::string name;
  std::uint64_t first_tick = 0, last_tick = 0;  // every tick in between looked as the picture
  Pixels lossless;                               // the Raw viewer's, the server's pixels
  Pixels jpeg;                                   // the Tight JPEG viewer's, what a browser gets
  /// An even tick in the middle of the span: the replay draws frame k at tick 2k (60 Hz ticks, 30 fps).
  [[nodiscard]] std::uint64_t tick() const { return (first_tick + last_tick) / 4 * 2; }
};

// The two viewers of the live session, read in turns so that neither falls behind.
struct Viewers {
  test::LosslessRfbClient& participant;
  test::RfbTestClient& browser;

  void pump(std::chrono::milliseconds duration) {
    const auto deadline = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < deadline) {
      REQUIRE(participant.pump(std::chrono::milliseconds(10)));
      browser.pump_until([] { return false; }, std::chrono::milliseconds(10));
      REQUIRE(browser.connected());
    }
  }

  void hold_key(std::uint32_t keysym, std::chrono::milliseconds held) {
    participant.send_key(keysym, true);
    pump(held);
    participant.send_key(keysym, false);
  }
};

// Waits until sim_rfb has rendered no new frame over at least 24 ticks (0.4 s), then takes both viewers'
// pictures, and checks that still no new frame was rendered meanwhile: the pictures are then the world's
// look at every tick of the span. Gives up after 30 s of a world that never rests.
Still capture_still(const std::string& name, int port, Viewers& viewers) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  SimStatus before = status_of(port);
  while (std::chrono::steady_clock::now() < deadline) {
    viewers.pump(std::chrono::milliseconds(500));
    const SimStatus now = status_of(port);
    if (now.frames != before.frames || now.tick < before.tick + 24) {
      before = now;
      continue;
    }
    REQUIRE(viewers.participant.refresh(std::chrono::seconds(10)));
    viewers.pump(std::chrono::milliseconds(200));
    const SimStatus after = status_of(port);
    if (after.frames != before.frames) {  // the picture changed while we took it: try again
      before = after;
      continue;
    }
    // The span ends at `now`: frames drawn after that tick are only known unchanged up to `after`'s loop.
    return Still{name, before.tick, now.tick, viewers.participant.rgb(), rgb_of(viewers.browser.frame())};
  }
  FAIL("the world of '" << name << "' never held still for 0.4 s within 30 s");
  return {};
}

}  // namespace

TEST_CASE("the replay's video shows the frames sim_rfb served at the same ticks within H.264's loss", "[waits]") {
  if (std::string(RFBSIM_FFMPEG).empty()) RFBSIM_SKIP("ffmpeg not found at configure time (apt-get install ffmpeg)");
  const auto dir = test::fresh_dir("served_frames");
  std::vector<Still> stills;
  {
    test::SimProcess sim(test::sim_rfb_path(),
                         {"--port", "0", "--scenario", RFBSIM_STILL_SCENARIO, "--data-dir", dir.string(), "--width",
                          std::to_string(kWidth), "--height", std::to_string(kHeight), "--uid", "p-frames"});
    // The participant sees the server's pixels exactly; a second viewer gets Tight JPEG at the server's
    // quality, as the participant's browser does.
    test::LosslessRfbClient participant("127.0.0.1", sim.port());
    test::RfbTestClient browser("127.0.0.1", sim.port());
    REQUIRE(participant.width() == kWidth);
    REQUIRE(participant.height() == kHeight);
    Viewers viewers{participant, browser};

    // Three moments far apart in the picture: the start, a metre or so further on, then turned left.
    stills.push_back(capture_still("start", sim.port(), viewers));
    viewers.hold_key('w', std::chrono::milliseconds(1500));
    stills.push_back(capture_still("walked", sim.port(), viewers));
    viewers.hold_key('a', std::chrono::milliseconds(1000));
    stills.push_back(capture_still("turned", sim.port(), viewers));

    const int status = sim.stop(SIGTERM);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
  }

  // The session as recorded: the frame rate and size the replay films at, and the end it films to.
  const sim::SessionLog log = sim::read_session(dir);
  REQUIRE(log.meta.tick_hz == 60);
  REQUIRE(log.meta.fps == 30);
  REQUIRE(log.meta.frame_width == kWidth);
  REQUIRE(log.meta.frame_height == kHeight);
  REQUIRE(log.meta.end_tick.has_value());

  const auto video = dir.parent_path() / "served_frames.mp4";
  const test::ReplayRun run = test::run_replay({dir.string(), "--video", video.string(), "-q"});
  INFO(run.output);
  REQUIRE(run.exit_code == 0);

  std::vector<std::uint64_t> indices;
  std::vector<sim::TrajectoryRow> still_poses;  // the avatar's pose at each still
  for (const Still& still : stills) {
    INFO(still.name << ": ticks " << still.first_tick << ".." << still.last_tick);
    REQUIRE(still.tick() < *log.meta.end_tick);
    indices.push_back(still.tick() / 2);
    // The log agrees that the avatar stood still over the span the live status showed (a row every 6 ticks).
    std::vector<const sim::TrajectoryRow*> rows;
    for (const sim::TrajectoryRow& row : log.trajectory) {
      if (row.kind == sim::AgentKind::Avatar && row.tick >= still.first_tick && row.tick <= still.last_tick) {
        rows.push_back(&row);
      }
    }
    REQUIRE(rows.size() >= 3);
    for (const sim::TrajectoryRow* row : rows) {
      CHECK(row->x == rows.front()->x);
      CHECK(row->y == rows.front()->y);
      CHECK(row->yaw == rows.front()->yaw);
    }
    still_poses.push_back(*rows.front());
  }
  // The keys did move the avatar between the stills (a stalled sim_rfb could apply a press and its release
  // in one tick): the three moments are different pictures.
  REQUIRE(still_poses.size() == 3);
  CHECK(std::hypot(still_poses[1].x - still_poses[0].x, still_poses[1].y - still_poses[0].y) > 0.5);
  CHECK(std::abs(still_poses[2].yaw - still_poses[1].yaw) > 0.3);
  const std::vector<Pixels> frames =
      test::decoded_frames(video, indices, kWidth, kHeight, dir.parent_path() / "served_frames.rgb");

  for (std::size_t i = 0; i < stills.size(); ++i) {
    const Still& still = stills[i];
    // The same moment: within H.264's loss (and JPEG's, for the browser's picture).
    const double lossless_mad = mean_abs_difference(still.lossless, frames[i]);
    const double lossless_psnr = psnr(still.lossless, frames[i]);
    const double jpeg_mad = mean_abs_difference(still.jpeg, frames[i]);
    const double jpeg_psnr = psnr(still.jpeg, frames[i]);
    INFO(still.name << " at tick " << still.tick() << " (frame " << indices[i] << "): raw MAD " << lossless_mad
                    << ", PSNR " << lossless_psnr << " dB; JPEG MAD " << jpeg_mad << ", PSNR " << jpeg_psnr << " dB");
    CHECK(lossless_mad < kLossless.max_mad);
    CHECK(lossless_psnr > kLossless.min_psnr);
    CHECK(jpeg_mad < kJpeg.max_mad);
    CHECK(jpeg_psnr > kJpeg.min_psnr);

    // Another moment does not pass for this one: the comparison can fail.
    for (std::size_t j = 0; j < stills.size(); ++j) {
      if (j == i) continue;
      INFO(still.name << " against the video at " << stills[j].name << ": MAD "
                      << mean_abs_difference(still.lossless, frames[j]) << ", PSNR " << psnr(still.lossless, frames[j])
                      << " dB");
      CHECK_FALSE(test::matches(still.lossless, frames[j], kLossless));
      CHECK_FALSE(test::matches(still.jpeg, frames[j], kJpeg));
    }
  }
  std::filesystem::remove_all(dir);
  std::filesystem::remove(video);
  std::filesystem::remove(dir.parent_path() / "served_frames.rgb");
}
