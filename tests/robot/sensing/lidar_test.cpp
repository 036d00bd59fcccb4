// SPDX-License-Identifier: GPL-2.0-or-later
// The lidar in a 5 x 4 m box room at 0.1 m (inner wall faces at x 0.1 and 4.9, y 0.1 and 3.9): exact
// ranges to walls and bodies, the noise's mean and spread, no-return beams, and poses that make no sense.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "robot/sensing/lidar.hpp"
#include "sensing_test_support.hpp"

using namespace rfbsim::sim;
using rfbsim::sim::test::walled_room;

namespace {

LidarParams noiseless() {
  LidarParams params;
  params.noise_stddev = 0.0;
  return params;
}

float range_of(const LaserScan& scan, int beam) { return scan.ranges.at(static_cast<std::size_t>(beam)); }

}  // namespace

TEST_CASE("lidar: a 360 beam scan is laid out from straight back, counter-clockwise") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const LaserScan scan = cast_scan(room, {}, {2.0, 1.5, 0.0}, 12.5, LidarParams{}, rng);
  CHECK(scan.ranges.size() == 360);
  CHECK(scan.time == 12.5);
  CHECK(scan.angle_min == Approx(-std::numbers::pi));
  CHECK(scan.angle_increment == Approx(std::numbers::pi / 180));
  CHECK(scan.range_min == 0.12);
  CHECK(scan.range_max == 8.0);
  CHECK(beam_angle(scan, 180) == Approx(0.0).margin(1e-12));
  CHECK(beam_angle(scan, 90) == Approx(-std::numbers::pi / 2));
  // A 270 degree scanner with 271 beams has a beam at each edge, one degree apart.
  LidarParams partial;
  partial.fov = 1.5 * std::numbers::pi;
  partial.beams = 271;
  CHECK(lidar_angle_min(partial) == Approx(-0.75 * std::numbers::pi));
  CHECK(lidar_angle_increment(partial) == Approx(std::numbers::pi / 180));
}

TEST_CASE("lidar: beams straight at the walls read the exact distance") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const LaserScan scan = cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, noiseless(), rng);
  CHECK(range_of(scan, 180) == Approx(2.9).margin(1e-6));  // ahead: x 4.9
  CHECK(range_of(scan, 0) == Approx(1.9).margin(1e-6));    // behind: x 0.1
  CHECK(range_of(scan, 90) == Approx(1.4).margin(1e-6));   // right: y 0.1
  CHECK(range_of(scan, 270) == Approx(2.4).margin(1e-6));  // left: y 3.9
  // Turned to face +y, the beam ahead reads the north wall.
  const LaserScan turned = cast_scan(room, {}, {2.0, 1.5, std::numbers::pi / 2}, 0.0, noiseless(), rng);
  CHECK(range_of(turned, 180) == Approx(2.4).margin(1e-6));
  CHECK(range_of(turned, 90) == Approx(2.9).margin(1e-6));
}

TEST_CASE("lidar: a beam at an angle to the wall reads d / cos(angle)") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const LaserScan scan = cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, noiseless(), rng);
  // East wall (2.9 m ahead) at 10, 30 and -20 degrees; the south wall (1.4 m) at -30 degrees is 60
  // degrees off its normal; the north wall (2.4 m) at 40 degrees is 50 degrees off its normal.
  const double degree = std::numbers::pi / 180;
  CHECK(range_of(scan, 190) == Approx(2.9 / std::cos(10 * degree)).margin(1e-5));
  CHECK(range_of(scan, 210) == Approx(2.9 / std::cos(30 * degree)).margin(1e-5));
  CHECK(range_of(scan, 160) == Approx(2.9 / std::cos(20 * degree)).margin(1e-5));
  CHECK(range_of(scan, 150) == Approx(1.4 / std::cos(60 * degree)).margin(1e-5));
  CHECK(range_of(scan, 220) == Approx(2.4 / std::cos(50 * degree)).margin(1e-5));
}

TEST_CASE("lidar: a person ahead reads centre distance minus radius, and hides the wall") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const std::vector<LidarBody> bodies = {{{3.0, 1.5}, 0.25}, {{2.0, 3.0}, 0.3}};
  const LaserScan scan = cast_scan(room, bodies, {2.0, 1.5, 0.0}, 0.0, noiseless(), rng);
  CHECK(range_of(scan, 180) == Approx(0.75).margin(1e-6));
  CHECK(range_of(scan, 270) == Approx(1.2).margin(1e-6));  // 1.5 - 0.3 to the left
  // One degree off centre the beam meets the circle at t = d cos(a) - sqrt(r^2 - d^2 sin^2(a)).
  const double a = std::numbers::pi / 180;
  CHECK(range_of(scan, 181) == Approx(std::cos(a) - std::sqrt(0.0625 - std::sin(a) * std::sin(a))).margin(1e-6));
  // Beside the person the beam reaches the wall again: the person spans about +-14.5 degrees at 1 m.
  CHECK(range_of(scan, 180 + 20) == Approx(2.9 / std::cos(20 * a)).margin(1e-5));
  // A body beyond a wall is not seen: a person outside the east wall.
  const std::vector<LidarBody> outside = {{{5.5, 1.5}, 0.25}};
  const LaserScan walled = cast_scan(room, outside, {2.0, 1.5, 0.0}, 0.0, noiseless(), rng);
  CHECK(range_of(walled, 180) == Approx(2.9).margin(1e-6));
}

TEST_CASE("lidar: ray-circle distances") {
  const LidarBody body{{2.0, 0.0}, 0.5};
  CHECK(*ray_circle_distance({0, 0}, {1, 0}, body) == Approx(1.5));
  CHECK_FALSE(ray_circle_distance({0, 0}, {-1, 0}, body));  // behind
  CHECK_FALSE(ray_circle_distance({0, 0}, {0, 1}, body));   // beside
  CHECK(*ray_circle_distance({2.1, 0.1}, {0, 1}, body) == 0.0);  // inside
}

TEST_CASE("lidar: the bodies are every person and the avatar, never the robot") {
  World world;
  world.people.push_back(Person{.id = 1, .pose = {1.0, 2.0, 0.0}, .radius = 0.25});
  world.people.push_back(Person{.id = 2, .pose = {3.0, 4.0, 0.0}, .radius = 0.3});
  world.avatar.pose = {5.0, 6.0, 0.0};
  world.avatar.radius = 0.35;
  world.robot = Robot{};
  world.robot->pose = {7.0, 8.0, 0.0};
  const std::vector<LidarBody> bodies = lidar_bodies(world);
  REQUIRE(bodies.size() == 3);
  CHECK(bodies[0].centre == Eigen::Vector2d(1.0, 2.0));
  CHECK(bodies[0].radius == 0.25);
  CHECK(bodies[1].centre == Eigen::Vector2d(3.0, 4.0));
  CHECK(bodies[1].radius == 0.3);
  CHECK(bodies[2].centre == Eigen::Vector2d(5.0, 6.0));
  CHECK(bodies[2].radius == 0.35);
}

TEST_CASE("lidar: noise averages to the true range with stddev sigma, returns only") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(7);
  const Pose2 pose{2.0, 1.5, 0.3};
  const LaserScan truth = cast_scan(room, {}, pose, 0.0, noiseless(), rng);
  const LidarParams noisy;  // sigma 0.01 m
  double sum = 0.0;
  double sum_sq = 0.0;
  int n = 0;
  for (int scan_index = 0; scan_index < 200; ++scan_index) {
    const LaserScan scan = cast_scan(room, {}, pose, 0.0, noisy, rng);
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double error = static_cast<double>(scan.ranges[i]) - static_cast<double>(truth.ranges[i]);
      sum += error;
      sum_sq += error * error;
      ++n;
    }
  }
  const double mean = sum / n;
  const double stddev = std::sqrt(sum_sq / n - mean * mean);
  // 72000 samples: the mean's own stddev is 0.01 / 268 = 4e-5 m, the stddev's about 0.3 %.
  CHECK(std::abs(mean) < 2e-4);
  CHECK(stddev == Approx(0.01).epsilon(0.02));
}

TEST_CASE("lidar: beams with nothing in range read exactly range_max, noise or not") {
  // A 20 x 20 m room seen with a 3.5 m lidar from the middle: no wall in range.
  const GridMap hall = walled_room(20.0, 20.0, 0.1);
  LidarParams params;
  params.range_max = 3.5;
  std::mt19937_64 rng(3);
  const std::vector<LidarBody> bodies = {{{12.0, 10.0}, 0.25}};
  const LaserScan scan = cast_scan(hall, bodies, {10.0, 10.0, 0.0}, 0.0, params, rng);
  int returns = 0;
  for (int i = 0; i < 360; ++i) {
    if (is_return(scan, range_of(scan, i))) {
      ++returns;
      CHECK(scan_point(scan, i, {10.0, 10.0, 0.0}));
    } else {
      CHECK(range_of(scan, i) == 3.5F);
      CHECK_FALSE(scan_point(scan, i, {10.0, 10.0, 0.0}));
    }
  }
  // Only the person 1.75 m ahead is seen, over +-asin(0.25 / 2) = +-7.2 degrees: beams -7..7.
  CHECK(returns == 15);
  CHECK(range_of(scan, 180) == Approx(1.75).margin(0.05));
}

TEST_CASE("lidar: returns stay between range_min and below range_max whatever the noise") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  LidarParams params;
  params.noise_stddev = 0.5;     // huge, so that clamping happens both ways
  params.range_max = 2.9;        // the wall ahead sits right at range_max
  std::mt19937_64 rng(11);
  // A person 0.3 m away (0.05 m to its surface: nearer than range_min) behind the lidar.
  const std::vector<LidarBody> bodies = {{{1.7, 1.5}, 0.25}};
  for (int k = 0; k < 20; ++k) {
    const LaserScan scan = cast_scan(room, bodies, {2.0, 1.5, 0.0}, 0.0, params, rng);
    for (const float r : scan.ranges) {
      CHECK(r >= 0.12F);
      CHECK(r <= 2.9F);
    }
  }
  // Without noise, the body nearer than range_min reads range_min.
  LidarParams exact = noiseless();
  const LaserScan scan = cast_scan(room, bodies, {2.0, 1.5, 0.0}, 0.0, exact, rng);
  CHECK(range_of(scan, 0) == 0.12F);
  CHECK(is_return(scan, range_of(scan, 0)));
}

TEST_CASE("lidar: scan points are the world points of returns") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const Pose2 pose{2.0, 1.5, std::numbers::pi / 2};
  const LaserScan scan = cast_scan(room, {}, pose, 0.0, noiseless(), rng);
  const auto ahead = scan_point(scan, 180, pose);
  REQUIRE(ahead);
  CHECK(ahead->x() == Approx(2.0).margin(1e-6));
  CHECK(ahead->y() == Approx(3.9).margin(1e-6));
  CHECK_FALSE(scan_point(scan, -1, pose));
  CHECK_FALSE(scan_point(scan, 360, pose));
  CHECK_FALSE(scan_point(scan, 180, {std::nan(""), 0.0, 0.0}));
}

TEST_CASE("lidar: poses that make no sense give clear scans, never a crash") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // Not finite: no returns at all.
  for (const Pose2& bad : {Pose2{nan, 1.0, 0.0}, Pose2{1.0, inf, 0.0}, Pose2{1.0, 1.0, nan}}) {
    const LaserScan scan = cast_scan(room, {}, bad, 0.0, LidarParams{}, rng);
    REQUIRE(scan.ranges.size() == 360);
    for (const float r : scan.ranges) CHECK(r == 8.0F);
  }
  // Off the map or inside a wall: the lidar is inside "wall" and reads range_min everywhere.
  for (const Pose2& blind : {Pose2{-3.0, 1.0, 0.0}, Pose2{1e300, -1e300, 0.0}, Pose2{0.05, 1.0, 0.0}}) {
    const LaserScan scan = cast_scan(room, {}, blind, 0.0, LidarParams{}, rng);
    for (const float r : scan.ranges) CHECK(r == 0.12F);
  }
  // Inside a person's body: likewise.
  const std::vector<LidarBody> body = {{{2.0, 1.5}, 0.25}};
  const LaserScan inside = cast_scan(room, body, {2.1, 1.5, 0.0}, 0.0, noiseless(), rng);
  for (const float r : inside.ranges) CHECK(r == 0.12F);
  // Bodies with NaN centres or no radius are ignored.
  const std::vector<LidarBody> broken = {{{nan, 1.5}, 0.25}, {{3.0, 1.5}, 0.0}, {{3.0, 1.5}, nan}};
  const LaserScan scan = cast_scan(room, broken, {2.0, 1.5, 0.0}, 0.0, noiseless(), rng);
  CHECK(range_of(scan, 180) == Approx(2.9).margin(1e-6));
  // An empty map: everything is off the grid.
  const LaserScan empty = cast_scan(GridMap{}, {}, {0.0, 0.0, 0.0}, 0.0, noiseless(), rng);
  CHECK(range_of(empty, 0) == 0.12F);
}

TEST_CASE("lidar: parameters that describe no lidar are refused by name") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 rng(1);
  LidarParams params;
  params.beams = 0;
  CHECK_THROWS_WITH(cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, params, rng), Catch::Contains("beams"));
  params = {};
  params.range_max = 0.1;
  CHECK_THROWS_WITH(cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, params, rng), Catch::Contains("range_max"));
  params = {};
  params.fov = 7.0;
  CHECK_THROWS_WITH(cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, params, rng), Catch::Contains("fov"));
  params = {};
  params.noise_stddev = -0.1;
  CHECK_THROWS_WITH(cast_scan(room, {}, {2.0, 1.5, 0.0}, 0.0, params, rng), Catch::Contains("noise_stddev"));
}

TEST_CASE("lidar: the same seed gives the same scans, another seed others") {
  const GridMap room = walled_room(5.0, 4.0, 0.1);
  std::mt19937_64 a(42);
  std::mt19937_64 b(42);
  std::mt19937_64 c(43);
  const LaserScan first = cast_scan(room, {}, {2.0, 1.5, 0.2}, 0.0, LidarParams{}, a);
  CHECK(first.ranges == cast_scan(room, {}, {2.0, 1.5, 0.2}, 0.0, LidarParams{}, b).ranges);
  CHECK(first.ranges != cast_scan(room, {}, {2.0, 1.5, 0.2}, 0.0, LidarParams{}, c).ranges);
}
