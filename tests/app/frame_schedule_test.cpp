// SPDX-License-Identifier: GPL-2.0-or-later
#include "app/frame_schedule.hpp"

#include <catch2/catch.hpp>

#include <vector>

namespace {

using namespace std::chrono_literals;
using rfbsim::sim::FrameSchedule;
using TimePoint = FrameSchedule::TimePoint;

const TimePoint t0 = TimePoint{} + 1h;

// sim_rfb's loop on a fake clock: it wakes at every 60 Hz tick (and at frame slots, which a 30 fps schedule puts
// on ticks too), steps one tick, and asks whether to render. Returns the times (ms from t0) it rendered.
struct Loop {
  FrameSchedule frames{std::chrono::nanoseconds(1'000'000'000 / 30)};
  std::vector<long> rendered;

  void run(long from_ms, long to_ms, bool watched = true) {
    for (long ms = from_ms; ms < to_ms; ms += 1) {
      // A tick is due every 1000/60 ms; the loop wakes for it (integer ms: ticks at 0, 16, 33, 50 ...).
      const bool tick = (ms * 60) / 1000 != ((ms - 1) * 60) / 1000 || ms == 0;
      if (!tick && !(watched && t0 + std::chrono::milliseconds(ms) >= frames.next_frame())) continue;
      if (frames.render_now(t0 + std::chrono::milliseconds(ms), tick ? 1 : 0, watched)) rendered.push_back(ms);
    }
  }
};

}  // namespace

TEST_CASE("frames follow the frame rate while nobody presses a key", "[frame_schedule]") {
  Loop loop;
  loop.run(0, 200);
  // 30 fps: about every 33 ms from the first viewer on.
  REQUIRE(loop.rendered.size() == 6);
  for (std::size_t i = 1; i < loop.rendered.size(); ++i) {
    CHECK(loop.rendered[i] - loop.rendered[i - 1] >= 33);
    CHECK(loop.rendered[i] - loop.rendered[i - 1] <= 34);
  }
}

TEST_CASE("a change of controls is rendered after the next tick, and the slots start again from it",
          "[frame_schedule]") {
  Loop loop;
  loop.run(0, 40);  // frames at 0 and 34 (whole ms); the next slot is at 67
  REQUIRE(loop.rendered == std::vector<long>{0, 34});
  loop.frames.controls_changed();  // a key at 40 ms, drained between ticks
  loop.run(40, 120);
  // Rendered at the next tick (50 ms), not at the 67 ms slot; then every 33 ms from there.
  REQUIRE(loop.rendered.size() >= 4);
  CHECK(loop.rendered[2] == 50);
  CHECK(loop.rendered[3] >= 83);
  CHECK(loop.rendered[3] <= 84);
}

TEST_CASE("a change drained in the same wake as its tick is rendered at once", "[frame_schedule]") {
  FrameSchedule frames(33ms);
  CHECK(frames.render_now(t0, 1, true));           // the first frame for a new viewer
  CHECK_FALSE(frames.render_now(t0 + 16ms, 1, true));
  frames.controls_changed();
  CHECK_FALSE(frames.render_now(t0 + 20ms, 0, true));  // no tick yet: the picture cannot show it
  CHECK(frames.render_now(t0 + 25ms, 1, true));          // the tick applied it
  CHECK(frames.next_frame() == t0 + 58ms);
  CHECK_FALSE(frames.render_now(t0 + 33ms, 1, true));    // the old slot is gone: no burst
}

TEST_CASE("nobody watching: nothing is rendered, and a change waits for no one", "[frame_schedule]") {
  FrameSchedule frames(33ms);
  frames.controls_changed();
  CHECK_FALSE(frames.render_now(t0, 1, false));
  // The first viewer gets a frame at once; the change before it does not bring another.
  CHECK(frames.render_now(t0 + 5ms, 0, true));
  CHECK_FALSE(frames.render_now(t0 + 10ms, 1, true));
}

TEST_CASE("a loop that fell behind skips the slots it missed instead of bursting", "[frame_schedule]") {
  FrameSchedule frames(33ms);
  CHECK(frames.render_now(t0, 1, true));
  CHECK(frames.render_now(t0 + 200ms, 1, true));  // a long stall
  CHECK(frames.next_frame() == t0 + 233ms);
  CHECK_FALSE(frames.render_now(t0 + 210ms, 1, true));
}
