// SPDX-License-Identifier: GPL-2.0-or-later
// Wheel odometry: perfect with a zero model, each systematic error on its own to the digit, random drift
// growing with the square root of the distance whatever the update rate, determinism per seed.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "robot/sensing/motion_delta.hpp"
#include "robot/sensing/odometry.hpp"
#include "sensing_test_support.hpp"

using namespace rfbsim::sim;
using rfbsim::sim::test::drive;
using rfbsim::sim::test::Segment;

namespace {

// Drives `segments` from `start` at `hz`, updating the odometry every tick; returns the final odometry pose.
Pose2 odometry_after(const OdometryParams& params, const Pose2& start, const std::vector<Segment>& segments,
                     double hz, std::uint64_t seed) {
  WheelOdometry odometry(params, start, seed);
  for (const Pose2& pose : drive(start, segments, hz)) odometry.update(pose);
  return odometry.pose();
}

// Stddev of the along-track (x) error after driving `metres` east at 0.5 m/s, over `runs` seeds.
double along_track_stddev(const OdometryParams& params, double metres, double hz, int runs) {
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int seed = 0; seed < runs; ++seed) {
    const auto run_seed = static_cast<std::uint64_t>(seed);
    const Pose2 end = odometry_after(params, {0, 0, 0}, {{0.5, 0.0, metres / 0.5}}, hz, run_seed);
    const double error = end.x - metres;
    sum += error;
    sum_sq += error * error;
  }
  const double mean = sum / runs;
  return std::sqrt(sum_sq / runs - mean * mean);
}

}  // namespace

TEST_CASE("odometry: a zero model follows the true path exactly, forwards, backwards and turning") {
  const OdometryParams perfect{0, 0, 0, 0, 0, 0, 0};
  const Pose2 start{1.0, 2.0, 0.5};
  const std::vector<Segment> segments = {{0.5, 0.0, 2.0}, {0.3, 1.0, 2.0}, {-0.2, -0.5, 2.0}, {0.0, 2.0, 3.0}};
  WheelOdometry odometry(perfect, start, 9);
  for (const Pose2& truth : drive(start, segments, 60.0)) {
    odometry.update(truth);
    REQUIRE(odometry.pose().x == Approx(truth.x).margin(1e-9));
    REQUIRE(odometry.pose().y == Approx(truth.y).margin(1e-9));
    REQUIRE(normalize_angle(odometry.pose().yaw - truth.yaw) == Approx(0.0).margin(1e-9));
  }
  // 1 m + 0.6 m of arc + 0.4 m reversing.
  CHECK(odometry.distance() == Approx(2.0).margin(1e-9));
}

TEST_CASE("odometry: a 1 % scale error reads 10 m as 10.1 m, forwards and backwards") {
  OdometryParams scale{0, 0, 0, 0, 0, 0, 0};
  scale.trans_scale_error = 0.01;
  const Pose2 forward = odometry_after(scale, {1.0, 2.0, 0.0}, {{0.5, 0.0, 20.0}}, 60.0, 1);
  CHECK(forward.x == Approx(11.1).margin(1e-9));
  CHECK(forward.y == Approx(2.0).margin(1e-9));
  CHECK(forward.yaw == Approx(0.0).margin(1e-12));
  // Diagonal and backwards: 10 m reversing along 45 degrees reads 10.1 m back along it.
  const Pose2 back = odometry_after(scale, {0.0, 0.0, std::numbers::pi / 4}, {{-0.5, 0.0, 20.0}}, 60.0, 1);
  CHECK(std::hypot(back.x, back.y) == Approx(10.1).margin(1e-9));
  CHECK(back.x < 0.0);
}

TEST_CASE("odometry: yaw drift turns a straight drive, rotation scale scales turns") {
  OdometryParams drift{0, 0, 0, 0, 0, 0, 0};
  drift.yaw_drift_per_m = 0.01;
  // 10 m straight: the odometry believes it turned 0.1 rad, on a circular arc of radius 100 m.
  const Pose2 arc = odometry_after(drift, {0.0, 0.0, 0.0}, {{0.5, 0.0, 20.0}}, 60.0, 1);
  CHECK(arc.yaw == Approx(0.1).margin(1e-9));
  CHECK(arc.x == Approx(100.0 * std::sin(0.1)).margin(1e-4));
  CHECK(arc.y == Approx(100.0 * (1.0 - std::cos(0.1))).margin(1e-4));
  OdometryParams turns{0, 0, 0, 0, 0, 0, 0};
  turns.rot_scale_error = 0.05;
  // Two radians in place read 2.1 rad; position unchanged.
  const Pose2 spun = odometry_after(turns, {3.0, 4.0, 0.0}, {{0.0, 1.0, 2.0}}, 60.0, 1);
  CHECK(spun.yaw == Approx(2.1).margin(1e-9));
  CHECK(spun.x == Approx(3.0).margin(1e-12));
  CHECK(spun.y == Approx(4.0).margin(1e-12));
}

TEST_CASE("odometry: random drift grows with the square root of the distance, whatever the update rate") {
  OdometryParams noise{0, 0, 0, 0, 0, 0, 0};
  noise.trans_stddev_per_m = 0.01;
  // 400 runs: the sample stddev is within 7 % of the true one with near certainty (3.5 sigma).
  const double one = along_track_stddev(noise, 1.0, 60.0, 400);
  const double nine = along_track_stddev(noise, 9.0, 60.0, 400);
  CHECK(one == Approx(0.01).epsilon(0.12));
  CHECK(nine == Approx(0.03).epsilon(0.12));
  // At 10 Hz updates the same drive drifts as much as at 60 Hz.
  const double slow = along_track_stddev(noise, 9.0, 10.0, 400);
  CHECK(slow == Approx(0.03).epsilon(0.12));
}

TEST_CASE("odometry: heading noise from turning grows with the angle turned") {
  OdometryParams noise{0, 0, 0, 0, 0, 0, 0};
  noise.rot_stddev_per_rad = 0.02;
  double sum_sq = 0.0;
  const int runs = 400;
  for (int seed = 0; seed < runs; ++seed) {
    // Four radians in place: heading stddev 0.02 * sqrt(4) = 0.04 rad.
    const Pose2 end = odometry_after(noise, {0, 0, 0}, {{0.0, 1.0, 4.0}}, 60.0, static_cast<std::uint64_t>(seed));
    const double error = normalize_angle(end.yaw - 4.0);
    sum_sq += error * error;
  }
  CHECK(std::sqrt(sum_sq / runs) == Approx(0.04).epsilon(0.12));
}

TEST_CASE("odometry: a robot jittering on the spot gathers no drift") {
  // Physics jitter: the true pose wanders by micrometres in random directions every tick for 60 s.
  const OdometryParams defaults;
  WheelOdometry odometry(defaults, {2.0, 3.0, 1.0}, 5);
  std::mt19937_64 rng(17);
  std::normal_distribution<double> jitter(0.0, 1e-6);
  for (int tick = 0; tick < 3600; ++tick) odometry.update({2.0 + jitter(rng), 3.0 + jitter(rng), 1.0 + jitter(rng)});
  CHECK(odometry.pose().x == Approx(2.0).margin(1e-3));
  CHECK(odometry.pose().y == Approx(3.0).margin(1e-3));
  CHECK(odometry.pose().yaw == Approx(1.0).margin(1e-3));
}

TEST_CASE("odometry: the same seed drifts the same way, another seed another way") {
  const OdometryParams defaults;
  const std::vector<Segment> segments = {{0.5, 0.3, 6.0}};
  const Pose2 a = odometry_after(defaults, {0, 0, 0}, segments, 60.0, 123);
  const Pose2 b = odometry_after(defaults, {0, 0, 0}, segments, 60.0, 123);
  const Pose2 c = odometry_after(defaults, {0, 0, 0}, segments, 60.0, 124);
  CHECK(a.x == b.x);
  CHECK(a.y == b.y);
  CHECK(a.yaw == b.yaw);
  CHECK(a.x != c.x);
  // The default model drifts a little, not a lot: over 3 m, millimetres to centimetres.
  const Pose2 truth = drive({0, 0, 0}, segments, 60.0).back();
  const double error = std::hypot(a.x - truth.x, a.y - truth.y);
  CHECK(error > 1e-4);
  CHECK(error < 0.1);
}

TEST_CASE("odometry: a non-finite true pose is ignored") {
  WheelOdometry odometry(OdometryParams{}, {1.0, 1.0, 0.0}, 1);
  CHECK_FALSE(odometry.update({std::nan(""), 1.0, 0.0}));
  CHECK(odometry.pose().x == 1.0);
  CHECK(odometry.update({1.5, 1.0, 0.0}));
  CHECK(odometry.pose().x == Approx(1.5).margin(0.01));
}
