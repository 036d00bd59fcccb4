// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA's trajectory generator: the dynamic window, the sampled velocities, and exact-arc rollouts.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robot/planning/dwa_rollout.hpp"

using namespace rfbsim::sim;

TEST_CASE("the dynamic window is one period of acceleration around the current velocity, within the limits") {
  const DwaParams params;  // 10 Hz, 1 m/s^2, 2 rad/s^2, 0..0.3 m/s, +-1 rad/s
  VelocityWindow window = dynamic_window(params, 0.0, 0.0);
  CHECK(window.v_min == 0.0);
  CHECK(window.v_max == Approx(0.1));
  CHECK(window.w_min == Approx(-0.2));
  CHECK(window.w_max == Approx(0.2));
  window = dynamic_window(params, 0.25, 0.95);
  CHECK(window.v_min == Approx(0.15));
  CHECK(window.v_max == 0.3);
  CHECK(window.w_min == Approx(0.75));
  CHECK(window.w_max == 1.0);
  // Pushed beyond the limits: the nearest limit only.
  window = dynamic_window(params, 0.8, -2.0);
  CHECK(window.v_min == 0.3);
  CHECK(window.v_max == 0.3);
  CHECK(window.w_min == -1.0);
  CHECK(window.w_max == -1.0);
}

TEST_CASE("samples span the window evenly and include zero when it lies inside") {
  std::vector<double> samples;
  velocity_samples(0.0, 0.1, 6, samples);
  REQUIRE(samples.size() == 6);
  for (std::size_t i = 0; i < 6; ++i) CHECK(samples[i] == Approx(0.02 * static_cast<double>(i)).margin(1e-15));
  CHECK(samples.back() == 0.1);

  velocity_samples(-0.2, 0.2, 20, samples);
  REQUIRE(samples.size() == 21);
  CHECK(samples.front() == -0.2);
  CHECK(samples.back() == 0.2);
  CHECK(std::count(samples.begin(), samples.end(), 0.0) == 1);
  CHECK(std::is_sorted(samples.begin(), samples.end()));

  velocity_samples(0.3, 0.3, 6, samples);
  CHECK(samples == std::vector<double>{0.3});
  velocity_samples(0.1, 0.2, 1, samples);  // at least both ends
  CHECK(samples == std::vector<double>{0.1, 0.2});
}

TEST_CASE("a rollout follows the exact arc in steps no longer than the granularities") {
  const DwaParams params;  // 1.7 s, 0.025 m, 0.1 rad, 0.2 s stop buffer
  Rollout rollout;
  SECTION("straight: 21 steps of 0.0243 m to 0.51 m, then 3 more for the stop buffer") {
    REQUIRE(roll_out({1.0, 2.0, std::numbers::pi / 2}, 0.3, 0.0, params, rollout));
    CHECK(rollout.end == 21);
    CHECK(rollout.poses.size() == 25);
    CHECK(rollout.poses[rollout.end].x == Approx(1.0));
    CHECK(rollout.poses[rollout.end].y == Approx(2.51));
    CHECK(rollout.poses.back().y == Approx(2.0 + 0.3 * 1.7 * 24 / 21));
  }
  SECTION("an arc ends on its circle") {
    REQUIRE(roll_out({0.0, 0.0, 0.0}, 0.2, 0.5, params, rollout));
    const Pose2& end = rollout.poses[rollout.end];
    // Centre (0, 0.4), radius 0.4, swept 0.85 rad.
    CHECK(end.x == Approx(0.4 * std::sin(0.85)));
    CHECK(end.y == Approx(0.4 - 0.4 * std::cos(0.85)));
    CHECK(end.yaw == Approx(0.85));
    CHECK(rollout.end == 14);  // 0.34 m / 0.025 m = 13.6 steps
  }
  SECTION("in place: 17 steps of 0.1 rad, never moving") {
    REQUIRE(roll_out({0.5, 0.5, 0.0}, 0.0, -1.0, params, rollout));
    CHECK(rollout.end == 17);
    for (const Pose2& p : rollout.poses) {
      CHECK(p.x == 0.5);
      CHECK(p.y == 0.5);
    }
    CHECK(rollout.poses[rollout.end].yaw == Approx(-1.7));
  }
  SECTION("standing still is no rollout") {
    CHECK_FALSE(roll_out({0.0, 0.0, 0.0}, 0.0, 0.0, params, rollout));
  }
}
