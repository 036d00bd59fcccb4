// SPDX-License-Identifier: GPL-2.0-or-later
#include "adaptive_quality.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

namespace {

using namespace std::chrono_literals;
using rfbsim::detail::AdaptiveQuality;
using rfbsim::detail::jpeg_size_ratio;
using rfbsim::detail::quality_ladder;
using rfbsim::detail::QualityLevel;
using TimePoint = AdaptiveQuality::TimePoint;

const TimePoint t_start = TimePoint{} + 1h;

std::vector<int> qualities(const std::vector<QualityLevel>& ladder) {
  std::vector<int> q;
  for (const auto& level : ladder) q.push_back(level.jpeg_quality);
  return q;
}

// A 25 fps stream on a fake clock: frame k is offered at t_start + 40 ms * k, as the server would drive it.
struct Stream {
  AdaptiveQuality aq;
  int tick = 0;
  std::vector<int> changes;  // ticks at which the level changed

  [[nodiscard]] TimePoint now() const { return t_start + tick * 40ms; }
  // One frame: offered, the rules applied, then (unless held) encoded at current() and sent.
  void frame(bool held, std::size_t bytes, double rate) {
    aq.frame_offered(now(), held);
    if (aq.adjust(now(), rate)) changes.push_back(tick);
    if (!held) aq.frame_sent(now(), bytes);
    ++tick;
  }
  void run_until(int end_tick, bool held, std::size_t bytes, double rate) {
    while (tick < end_tick) frame(held, bytes, rate);
  }
};

// With every frame held from t_start, the first step down comes at tick 38: 1.5 s hold-off, 40 ms ticks.
void step_down_once(Stream& s) {
  s.run_until(39, true, 0, 0);
  REQUIRE(s.changes == std::vector<int>{38});
  REQUIRE(s.aq.level() == 1);
}

// After step_down_once: steps up after the 3 s calm, then fails at once and steps down again.
void fail_one_step_up(Stream& s) {
  s.run_until(114, false, 10000, 0);  // up at tick 113 (4.52 s)
  s.run_until(152, true, 0, 0);       // held at once: down after the hold-off, at 6.04 s
  REQUIRE(s.changes == std::vector<int>{38, 113, 151});
}

}  // namespace

TEST_CASE("the ladder runs from the top quality to the floor, 4:2:0", "[adaptive_quality]") {
  CHECK(qualities(quality_ladder(80, 20)) == std::vector<int>{80, 64, 48, 36, 20});
  CHECK(qualities(quality_ladder(90, 20)) == std::vector<int>{90, 72, 54, 41, 20});
  CHECK(qualities(quality_ladder(30, 20)) == std::vector<int>{30, 24, 20});
  CHECK(qualities(quality_ladder(20, 20)) == std::vector<int>{20});
  CHECK(qualities(quality_ladder(10, 20)) == std::vector<int>{10});  // never above the top
  CHECK(qualities(quality_ladder(150, 20)).front() == 100);
  for (const auto& level : quality_ladder(80, 20)) CHECK(level.subsampling == 1);
  AdaptiveQuality aq;
  CHECK(aq.level() == 0);
  CHECK(aq.current() == QualityLevel{80, 1});
  CHECK(aq.levels().size() == 5);
}

TEST_CASE("the size model grows with quality", "[adaptive_quality]") {
  CHECK(jpeg_size_ratio(80, 80) == 1.0);
  CHECK(jpeg_size_ratio(64, 80) == Approx(1.4229).epsilon(1e-4));  // (72 / 40)^0.6
  CHECK(jpeg_size_ratio(80, 64) == Approx(1 / 1.4229).epsilon(1e-4));
  CHECK(jpeg_size_ratio(20, 36) > 1.0);
  CHECK(jpeg_size_ratio(90, 100) > jpeg_size_ratio(90, 95));
}

TEST_CASE("held frames step the quality down one level per hold-off, to the floor", "[adaptive_quality]") {
  Stream s;
  s.run_until(38, true, 0, 0);
  CHECK(s.aq.level() == 0);  // 37 ticks = 1.48 s: still inside the first hold-off
  s.run_until(76, true, 0, 0);
  CHECK(s.aq.level() == 1);  // tick 75 = 1.48 s after the change
  s.run_until(400, true, 0, 0);
  CHECK(s.changes == std::vector<int>{38, 76, 114, 152});
  CHECK(s.aq.level() == 4);
  CHECK(s.aq.current() == QualityLevel{20, 1});  // and never below
}

TEST_CASE("a small share of held frames does not step down", "[adaptive_quality]") {
  Stream s;
  SECTION("one in five (20%) stays") {
    for (int k = 0; k < 500; ++k) s.frame(k % 5 == 0, 10000, 0);
    CHECK(s.changes.empty());
  }
  SECTION("one in three (32% of the window) steps down") {
    for (int k = 0; k < 39; ++k) s.frame(k % 3 == 0, 10000, 0);
    CHECK(s.changes == std::vector<int>{38});
  }
}

// At level 1 (q64) sending 10000 bytes a frame at 25 fps, the next level up should take
// 1.25 x 25 x 10000 x 1.4229 = 444.7 KB/s.
TEST_CASE("the quality steps up after a calm only when the rate allows", "[adaptive_quality]") {
  Stream s;
  step_down_once(s);  // the last held frame is tick 38 (1.52 s)
  SECTION("enough rate: up 3 s after the last held frame, and never above the top") {
    s.run_until(113, false, 10000, 450000);
    CHECK(s.aq.level() == 1);
    CHECK(s.aq.next_level_bytes() == Approx(14229).epsilon(1e-4));
    s.run_until(1000, false, 10000, 450000);
    CHECK(s.changes == std::vector<int>{38, 113});
    CHECK(s.aq.level() == 0);
  }
  SECTION("unknown rate: nothing says no") {
    s.run_until(200, false, 10000, 0);
    CHECK(s.changes == std::vector<int>{38, 113});
  }
  SECTION("too little rate: only a probe after 30 s") {
    s.run_until(788, false, 10000, 440000);
    CHECK(s.aq.level() == 1);
    s.run_until(789, false, 10000, 440000);
    CHECK(s.changes == std::vector<int>{38, 788});
  }
  SECTION("a held frame restarts the calm") {
    s.run_until(60, false, 10000, 450000);
    s.frame(true, 0, 450000);  // tick 60, 2.4 s
    s.run_until(200, false, 10000, 450000);
    CHECK(s.changes == std::vector<int>{38, 135});
  }
}

TEST_CASE("a failed step up doubles the next wait", "[adaptive_quality]") {
  Stream s;
  step_down_once(s);
  fail_one_step_up(s);
  s.run_until(400, false, 10000, 0);  // the calm must now last 6 s: up at 12.04 s
  CHECK(s.changes == std::vector<int>{38, 113, 151, 301});
}

TEST_CASE("a lasting step up resets a doubled wait", "[adaptive_quality]") {
  Stream s;
  step_down_once(s);
  fail_one_step_up(s);
  s.run_until(400, false, 10000, 0);  // the doubled wait: up at 12.04 s
  REQUIRE(s.changes == std::vector<int>{38, 113, 151, 301});
  s.run_until(600, false, 10000, 0);  // 12 s at the top: the probation passed
  s.run_until(607, true, 0, 0);       // 7 of 25 held at tick 606: down again
  s.run_until(800, false, 10000, 0);  // back to the 3 s wait: up at 27.24 s
  CHECK(s.changes == std::vector<int>{38, 113, 151, 301, 606, 681});
}

namespace {

// A link of `capacity` bytes/s behind a sender that holds a frame while more than a window (40 KB) is
// still queued, as congestion control does once settled: offering more than the capacity holds about
// 1 - capacity / demand of the frames. The true bytes per frame of each level are `sizes`; the rate
// estimate is the capacity, as congestion control measures it while frames are held.
struct BorderlineLink {
  double capacity;
  std::vector<std::size_t> sizes;
  TimePoint drained = t_start;
  int ticks_at_level_one = 0;

  void run(Stream& s, int ticks) {
    for (int k = 0; k < ticks; ++k) {
      const std::chrono::duration<double> backlog = drained - s.now();
      const bool held = backlog.count() * capacity > 40000;
      const std::size_t bytes = sizes[s.aq.level()];
      if (!held) {
        const std::chrono::duration<double> busy(static_cast<double>(bytes) / capacity);
        drained = std::max(drained, s.now()) + std::chrono::duration_cast<TimePoint::duration>(busy);
      }
      ticks_at_level_one += s.aq.level() == 1 ? 1 : 0;
      s.frame(held, bytes, capacity);
    }
  }
};

}  // namespace

TEST_CASE("a steady borderline link does not make the quality oscillate", "[adaptive_quality]") {
  Stream s;
  constexpr int kTicks = 3000;  // two minutes
  SECTION("the top level loses a few frames: below the share, it stays") {
    BorderlineLink link{420000, {20000, 14000, 10000, 8000, 6000}};  // top needs 500 KB/s: ~16% held
    link.run(s, kTicks);
    CHECK(s.changes.empty());
  }
  SECTION("level 1 loses a few frames too: down once, and the rate keeps it there") {
    BorderlineLink link{300000, {20000, 13000, 10000, 8000, 6000}};  // 500 and 325 KB/s
    link.run(s, kTicks);
    CHECK(s.changes.size() == 1);
    CHECK(link.ticks_at_level_one >= 0.95 * kTicks);
  }
  SECTION("level 1 fits: only probes, each failed one twice as far from the last") {
    BorderlineLink link{300000, {20000, 11000, 9000, 7000, 5000}};  // 500 and 275 KB/s
    link.run(s, kTicks);
    // Down at 1.52 s; a probe 30 s (750 ticks) after the last held frame, back down after the 1.5 s
    // hold-off; the next probe waits 60 s, and fails the same way.
    CHECK(s.changes == std::vector<int>{38, 788, 826, 2327, 2365});
    CHECK(link.ticks_at_level_one >= 0.95 * kTicks);
  }
}

TEST_CASE("a still picture sent below the top is refreshed once", "[adaptive_quality]") {
  Stream s;
  SECTION("not at the top level") {
    s.frame(false, 10000, 0);
    s.aq.scene_changed(s.now());
    CHECK_FALSE(s.aq.wants_still_refresh(s.now() + 10s));
  }
  SECTION("0.5 s after the last change, then not again until a new low frame") {
    step_down_once(s);
    const TimePoint t = s.now();
    s.aq.scene_changed(t);
    s.aq.frame_sent(t, 10000);
    CHECK_FALSE(s.aq.wants_still_refresh(t + 499ms));
    CHECK(s.aq.wants_still_refresh(t + 500ms));
    s.aq.still_refreshed();
    CHECK_FALSE(s.aq.wants_still_refresh(t + 2s));
    s.aq.scene_changed(t + 3s);  // damage alone: the screen still shows the refreshed picture
    CHECK_FALSE(s.aq.wants_still_refresh(t + 4s));
    s.aq.frame_sent(t + 4s, 10000);
    CHECK(s.aq.wants_still_refresh(t + 4s));  // still since t + 3 s
    s.aq.scene_changed(t + 4s + 300ms);       // more damage restarts the wait
    CHECK_FALSE(s.aq.wants_still_refresh(t + 4s + 700ms));
    CHECK(s.aq.wants_still_refresh(t + 4s + 800ms));
  }
}

namespace {

// A client that takes `per_frame` to show each picture whatever its size (a page decoding slowly, a busy
// laptop), behind a sender that holds a frame while the client still has one waiting, as congestion control
// does once its answers come late: offered at 25 fps, it takes what it can and the rest is held.
struct SlowClient {
  std::chrono::milliseconds per_frame;
  TimePoint free_at = t_start;
  int ticks_at_top = 0;

  void run(Stream& s, int ticks) {
    for (int k = 0; k < ticks; ++k) {
      const bool held = free_at > s.now() + per_frame;
      if (!held) free_at = std::max(free_at, s.now()) + per_frame;
      ticks_at_top += s.aq.level() == 0 ? 1 : 0;
      s.frame(held, 20000 - 3000 * s.aq.level(), 0);
    }
  }
};

}  // namespace

TEST_CASE("a client slow per picture keeps the top quality: a step down that sends no more frames is taken back",
          "[adaptive_quality]") {
  Stream s;
  SlowClient client{60ms};  // 16.7 of the 25 frames a second; a third held at every level
  client.run(s, 3000);      // two minutes
  // Down at 1.52 s, back after the hold-off (no more frames went out); the next try waits 30 s (750 ticks),
  // and the one after it 60 s.
  CHECK(s.changes == std::vector<int>{38, 76, 826, 864, 2364, 2402});
  CHECK(client.ticks_at_top >= 0.9 * 3000);
  CHECK_FALSE(s.aq.link_bound());
}

TEST_CASE("a slow link steps down while each step sends more frames, and the step counts as the link's",
          "[adaptive_quality]") {
  Stream s;
  // 200 KB/s: 10 fps at the top, 14 at level 1, 18 at level 2, and level 3 (7 KB) carries all 25.
  BorderlineLink link{200000, {20000, 14000, 11000, 7000, 5000}};
  link.run(s, 39);
  CHECK(s.aq.level() == 1);
  CHECK_FALSE(s.aq.link_bound());  // not yet judged
  link.run(s, 77 - 39);
  CHECK(s.aq.level() == 2);
  CHECK(s.aq.link_bound());  // the first step sent more frames: judged, kept, and the next one taken
  CHECK_FALSE(s.aq.client_bound(s.now()));
  link.run(s, 400);
  CHECK(s.aq.level() == 3);
  CHECK(s.aq.link_bound());
  CHECK(s.changes == std::vector<int>{38, 76, 115});
}
