// SPDX-License-Identifier: GPL-2.0-or-later
// The rot1, trans, rot2 split: exact round trips, reversing as a negative drive, turning in place.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "robot/sensing/motion_delta.hpp"

using namespace rfbsim::sim;

TEST_CASE("motion delta: angles wrap into the half-open range from -pi to pi") {
  CHECK(normalize_angle(0.5) == 0.5);
  CHECK(normalize_angle(-std::numbers::pi) == Approx(std::numbers::pi));
  CHECK(normalize_angle(std::numbers::pi) == Approx(std::numbers::pi));
  CHECK(normalize_angle(3 * std::numbers::pi) == Approx(std::numbers::pi));
  CHECK(normalize_angle(2 * std::numbers::pi + 0.25) == Approx(0.25));
  CHECK(normalize_angle(-2 * std::numbers::pi - 0.25) == Approx(-0.25));
  CHECK(std::isnan(normalize_angle(std::nan(""))));
}

TEST_CASE("motion delta: a forward drive with turns splits into turn, drive, turn") {
  const Pose2 from{1.0, 2.0, std::numbers::pi / 2};
  const Pose2 to{0.0, 3.0, std::numbers::pi};  // moved up-left by (-1, 1), now facing -x
  const MotionDelta d = decompose_motion(from, to, 0.0);
  CHECK(d.rot1 == Approx(std::numbers::pi / 4));   // from +y to the (-1, 1) direction
  CHECK(d.trans == Approx(std::sqrt(2.0)));
  CHECK(d.rot2 == Approx(std::numbers::pi / 4));
  const Pose2 back = compose_motion(from, d);
  CHECK(back.x == Approx(0.0).margin(1e-12));
  CHECK(back.y == Approx(3.0));
  CHECK(back.yaw == Approx(std::numbers::pi));
}

TEST_CASE("motion delta: reversing is a negative drive, not a half turn") {
  const MotionDelta d = decompose_motion({0.0, 0.0, 0.0}, {-0.5, 0.0, 0.1}, 0.0);
  CHECK(d.rot1 == Approx(0.0).margin(1e-12));
  CHECK(d.trans == Approx(-0.5));
  CHECK(d.rot2 == Approx(0.1));
  const Pose2 p = compose_motion({0.0, 0.0, 0.0}, d);
  CHECK(p.x == Approx(-0.5));
  CHECK(p.y == Approx(0.0).margin(1e-12));
}

TEST_CASE("motion delta: below min_trans the drive goes along the heading") {
  // 5 mm sideways with a 0.01 m minimum: no turn toward it, only the heading's share of it is driven.
  const MotionDelta d = decompose_motion({0.0, 0.0, 0.0}, {0.003, 0.004, 0.2}, 0.01);
  CHECK(d.rot1 == 0.0);
  CHECK(d.trans == Approx(0.003));
  CHECK(d.rot2 == Approx(0.2));
  const MotionDelta still = decompose_motion({1.0, 1.0, 0.3}, {1.0, 1.0, -0.3}, 0.0);
  CHECK(still.rot1 == 0.0);
  CHECK(still.trans == 0.0);
  CHECK(still.rot2 == Approx(-0.6));
}

TEST_CASE("motion delta: any motion round-trips exactly with min_trans 0") {
  const Pose2 from{3.0, -2.0, 2.9};
  for (const Pose2& to : {Pose2{3.1, -1.7, -3.0}, Pose2{2.0, -2.0, 2.9}, Pose2{3.0 + 1e-9, -2.0, 0.0},
                          Pose2{-4.0, 5.0, 1.0}}) {
    const Pose2 p = compose_motion(from, decompose_motion(from, to, 0.0));
    CHECK(p.x == Approx(to.x).margin(1e-12));
    CHECK(p.y == Approx(to.y).margin(1e-12));
    CHECK(normalize_angle(p.yaw - to.yaw) == Approx(0.0).margin(1e-12));
  }
}
