// SPDX-License-Identifier: GPL-2.0-or-later
// The differential drive's limits and wheel speeds, and the order in which missions hand out goals.
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include "robot/diff_drive.hpp"
#include "robot/mission.hpp"

namespace sim = rfbsim::sim;

TEST_CASE("drive: speeds up and brakes no faster than its acceleration limits", "[drive]") {
  sim::DriveLimits limits;
  sim::DiffDrive drive(limits);
  sim::Robot robot;
  robot.pose.yaw = M_PI / 2.0;
  drive.command(0.3, 0.0);
  const double dt = 1.0 / 60.0;
  drive.step(dt, robot);
  CHECK(drive.v() == Approx(limits.acc_lim_x * dt));
  // Along its heading (+y here), nothing sideways.
  CHECK(robot.velocity.x() == Approx(0.0).margin(1e-12));
  CHECK(robot.velocity.y() == Approx(limits.acc_lim_x * dt));
  for (int i = 0; i < 60; ++i) drive.step(dt, robot);
  CHECK(drive.v() == Approx(0.3));
  drive.command(0.0, 0.0);
  drive.step(dt, robot);
  CHECK(drive.v() == Approx(0.3 - limits.acc_lim_x * dt));
}

TEST_CASE("drive: commands beyond Kuri's limits are clamped, NaN stops", "[drive]") {
  sim::DiffDrive drive;
  sim::Robot robot;
  drive.command(5.0, -10.0);
  for (int i = 0; i < 600; ++i) drive.step(0.01, robot);
  CHECK(drive.v() == Approx(0.5));
  CHECK(drive.w() == Approx(-3.0));
  CHECK(robot.yaw_rate == Approx(-3.0));
  drive.command(std::nan(""), std::nan(""));
  for (int i = 0; i < 600; ++i) drive.step(0.01, robot);
  CHECK(drive.v() == 0.0);
  CHECK(drive.w() == 0.0);
  drive.command(0.2, 1.0);
  drive.step(0.01, robot);
  drive.halt(robot);
  CHECK(drive.v() == 0.0);
  CHECK(robot.velocity.norm() == 0.0);
}

TEST_CASE("drive: wheel speeds of a differential drive", "[drive]") {
  sim::DriveLimits limits;  // r 0.035 m, track 0.175 m
  const auto straight = sim::wheel_speeds(limits, 0.35, 0.0);
  CHECK(straight.left == Approx(10.0));
  CHECK(straight.right == Approx(10.0));
  const auto spin = sim::wheel_speeds(limits, 0.0, 2.0);
  CHECK(spin.left == Approx(-2.0 * 0.0875 / 0.035));
  CHECK(spin.right == Approx(2.0 * 0.0875 / 0.035));
}

namespace {

sim::MissionSpec mission(sim::MissionSpec::Kind kind, int places) {
  sim::MissionSpec spec;
  spec.kind = kind;
  for (int i = 0; i < places; ++i) {
    spec.waypoints.push_back({static_cast<double>(i), 0.0, 0.0});
    spec.waypoint_names.push_back("p" + std::to_string(i));
  }
  return spec;
}

}  // namespace

TEST_CASE("mission: goto hands out its goal once, none nothing", "[mission]") {
  sim::MissionRunner go(mission(sim::MissionSpec::Kind::GoTo, 1), 1);
  const auto goal = go.next_goal();
  REQUIRE(goal);
  CHECK(goal->x == 0.0);
  CHECK(go.goal_name() == "p0");
  CHECK_FALSE(go.next_goal());
  sim::MissionRunner none(mission(sim::MissionSpec::Kind::None, 2), 1);
  CHECK_FALSE(none.next_goal());
}

TEST_CASE("mission: patrol loops over its waypoints in order", "[mission]") {
  sim::MissionRunner patrol(mission(sim::MissionSpec::Kind::Patrol, 3), 1);
  for (int lap = 0; lap < 3; ++lap) {
    for (int i = 0; i < 3; ++i) CHECK(patrol.next_goal()->x == static_cast<double>(i));
  }
}

TEST_CASE("mission: wander never repeats a place twice in a row, visits all, and is seeded", "[mission]") {
  sim::MissionRunner a(mission(sim::MissionSpec::Kind::Wander, 4), 7);
  sim::MissionRunner b(mission(sim::MissionSpec::Kind::Wander, 4), 7);
  sim::MissionRunner c(mission(sim::MissionSpec::Kind::Wander, 4), 8);
  std::set<double> seen;
  double last = -1.0;
  bool differs = false;
  for (int i = 0; i < 200; ++i) {
    const double x = a.next_goal()->x;
    CHECK(x != last);
    CHECK(b.next_goal()->x == x);
    differs = differs || c.next_goal()->x != x;
    seen.insert(x);
    last = x;
  }
  CHECK(seen.size() == 4);
  CHECK(differs);
}
