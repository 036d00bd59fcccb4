// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA local planner on a 4 m x 4 m local costmap: full speed along a straight path, turning with a
// curving one, clear of an obstacle, toward a covered goal, stopping with a reason when nothing is legal,
// within the dynamic window, and turning in place toward a heading.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "planning_test_support.hpp"
#include "robot/planning/dwa_planner.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

constexpr double kWindowRes = 0.05;
// The robot stands at the centre of cell (40, 40) of an 80 x 80 window.
const Pose2 kRobot{2.025, 2.025, 0.0};

CostmapGrid free_window() { return CostmapGrid::sized(80, 80, kWindowRes, 0.0, 0.0); }

// Points every 2.5 cm from a to b.
std::vector<Eigen::Vector2d> line(Eigen::Vector2d a, Eigen::Vector2d b) {
  std::vector<Eigen::Vector2d> path;
  const int pieces = std::max(1, static_cast<int>(std::lround((b - a).norm() / 0.025)));
  for (int i = 0; i <= pieces; ++i) path.push_back(a + (b - a) * (static_cast<double>(i) / pieces));
  return path;
}

// Every point of the chosen trajectory in a cell below inscribed.
bool trajectory_clear(const CostmapGrid& grid, const DwaCommand& command) {
  return path_below(grid, command.trajectory, cost::kInscribed);
}

}  // namespace

TEST_CASE("with a straight path ahead in free space the robot drives straight at the fastest reachable speed") {
  DwaPlanner planner;
  planner.set_plan(line({2.025, 2.025}, {8.0, 2.025}));
  const CostmapGrid local = free_window();
  SECTION("from rest: one period of acceleration") {
    const DwaCommand command = planner.compute(local, kRobot, 0.0, 0.0);
    REQUIRE(command.found);
    CHECK(command.reason.empty());
    CHECK(command.v == Approx(0.1));
    CHECK(command.w == 0.0);
    CHECK(command.rollouts == 125);  // 6 speeds x 21 turn rates, less standing still
    REQUIRE(command.trajectory.size() == 8);  // 0.17 m in 7 steps
    CHECK(command.trajectory.front() == Eigen::Vector2d(kRobot.x, kRobot.y));
    CHECK(command.trajectory.back().x() == Approx(kRobot.x + 0.17));
    CHECK(command.trajectory.back().y() == Approx(kRobot.y));
    // The local goal: the last path point inside the window, 3.975 m.
    CHECK(planner.local_goal().x() > 3.95);
    CHECK(planner.local_goal().x() < 4.0);
  }
  SECTION("at full speed: keeps it") {
    const DwaCommand command = planner.compute(local, kRobot, 0.3, 0.0);
    REQUIRE(command.found);
    CHECK(command.v == 0.3);
    CHECK(command.w == 0.0);
    CHECK(command.rollouts == 126);  // the brake sample (0.2, 0) is already on the grid
  }
}

TEST_CASE("with the path curving left the robot turns left, and right for a right curve") {
  // A quarter circle of radius 0.6 m starting at the robot, heading +x.
  for (const double side : {1.0, -1.0}) {
    INFO("side " << side);
    std::vector<Eigen::Vector2d> arc;
    for (int i = 0; i <= 60; ++i) {
      const double a = 0.5 * std::numbers::pi * i / 60.0;
      arc.emplace_back(kRobot.x + 0.6 * std::sin(a), kRobot.y + side * 0.6 * (1.0 - std::cos(a)));
    }
    DwaPlanner planner;
    planner.set_plan(arc);
    const DwaCommand command = planner.compute(free_window(), kRobot, 0.3, 0.0);
    REQUIRE(command.found);
    CHECK(command.v > 0.0);
    CHECK(command.w * side >= 0.15);  // the window allows up to 0.2 rad/s this period
  }
}

TEST_CASE("with an obstacle straight ahead on the path the robot picks a rollout that keeps clear of it") {
  // A block across the path whose inscribed cells begin 0.175 m ahead: straight on at the fastest speed
  // reachable from rest (0.1 m/s, 0.19 m with the stop buffer) would enter them.
  CostmapGrid local = free_window();
  for (int row = 36; row <= 44; ++row) {
    for (int col = 47; col <= 50; ++col) local.set({col, row}, cost::kLethal);
  }
  inflate(local, 0.16, 0.2);
  DwaPlanner planner;
  planner.set_plan(line({2.025, 2.025}, {3.5, 2.025}));
  const DwaCommand command = planner.compute(local, kRobot, 0.0, 0.0);
  REQUIRE(command.found);
  CHECK(trajectory_clear(local, command));
  CHECK(command.v < 0.1);
  Rollout straight;
  REQUIRE(roll_out(kRobot, 0.1, 0.0, planner.params(), straight));
  bool hits = false;
  for (const Pose2& p : straight.poses) hits = hits || local.at_world(p.x, p.y) >= cost::kInscribed;
  CHECK(hits);
}

TEST_CASE("a goal covered by an obstacle is still approached") {
  // The path ends inside a lethal block (someone standing on the goal): the goal map grows from the last
  // free path cell instead, and the robot drives on toward it.
  CostmapGrid local = free_window();
  for (int row = 38; row <= 42; ++row) {
    for (int col = 60; col <= 64; ++col) local.set({col, row}, cost::kLethal);
  }
  DwaPlanner planner;
  planner.set_plan(line({2.025, 2.025}, {3.125, 2.025}));
  const DwaCommand command = planner.compute(local, kRobot, 0.3, 0.0);
  REQUIRE(command.found);
  CHECK(command.v == 0.3);
  CHECK(command.w == 0.0);
  CHECK(planner.local_goal().x() == Approx(3.125));
}

TEST_CASE("a robot too fast to stop within one period also gets the sample braking along its arc") {
  // From 0.25 m/s turning at 0.3 rad/s the window is v 0.15..0.3, w 0.1..0.5 (20 samples, no zero); the
  // brake sample (0.15, 0.18) keeps the curvature 1.2 and is not among them.
  DwaPlanner planner;
  planner.set_plan(line({2.025, 2.025}, {3.5, 2.5}));
  const DwaCommand command = planner.compute(free_window(), kRobot, 0.25, 0.3);
  REQUIRE(command.found);
  CHECK(command.rollouts == 6 * 20 + 1);
}

TEST_CASE("when every rollout is rejected the robot stops and the reason says by what") {
  CostmapGrid local = free_window();
  DwaPlanner planner;
  SECTION("walled in, with the path outside the walls") {
    // A ring of lethal cells around the robot's cell: driving hits it, turning in place leaves the path
    // out of reach.
    for (int row = 39; row <= 41; ++row) {
      for (int col = 39; col <= 41; ++col) {
        if (row != 40 || col != 40) local.set({col, row}, cost::kLethal);
      }
    }
    planner.set_plan(line({2.225, 2.025}, {3.5, 2.025}));
    const DwaCommand command = planner.compute(local, kRobot, 0.0, 0.0);
    CHECK_FALSE(command.found);
    CHECK(command.v == 0.0);
    CHECK(command.w == 0.0);
    CHECK(command.trajectory.empty());
    CHECK(command.reason ==
          "no legal rollout among 125: 105 hit obstacles or leave the local costmap, 20 end where the global path "
          "cannot be reached");
  }
  SECTION("standing in a lethal cell") {
    local.set({40, 40}, cost::kLethal);
    planner.set_plan(line({2.025, 2.025}, {3.5, 2.025}));
    const DwaCommand command = planner.compute(local, kRobot, 0.3, 0.0);
    CHECK_FALSE(command.found);
    CHECK(command.reason == "all 126 rollouts hit obstacles or leave the local costmap");
  }
}

TEST_CASE("bad input and a path away from the robot give reasons, not crashes") {
  DwaPlanner planner;
  const CostmapGrid local = free_window();
  CHECK(planner.compute(local, kRobot, 0.0, 0.0).reason == "no global path set");
  planner.set_plan({{2.0, 2.0}, {std::nan(""), 2.0}});
  CHECK(planner.compute(local, kRobot, 0.0, 0.0).reason == "the global path has a non-finite point");
  planner.set_plan(line({6.0, 2.0}, {8.0, 2.0}));
  CHECK(planner.compute(local, kRobot, 0.0, 0.0).reason.rfind("the global path leaves the local costmap at the robot", 0) == 0);
  planner.set_plan(line({2.0, 2.0}, {3.0, 2.0}));
  CHECK(planner.compute(local, {NAN, 1.0, 0.0}, 0.0, 0.0).reason == "the robot's pose is not finite");
  CHECK(planner.compute(local, kRobot, INFINITY, 0.0).reason == "the robot's velocity is not finite");
  CHECK(planner.compute(local, {5.0, 1.0, 0.0}, 0.0, 0.0).reason == "the robot (5.00, 1.00) is off the local costmap");
  CHECK_FALSE(planner.compute(CostmapGrid{}, kRobot, 0.0, 0.0).found);
  DwaParams bad;
  bad.sim_time = 0.0;
  CHECK(DwaPlanner(bad).compute(local, kRobot, 0.0, 0.0).reason.rfind("bad DWA parameters", 0) == 0);
}

TEST_CASE("every command lies in the dynamic window and the limits") {
  const DwaParams params;
  DwaPlanner planner(params);
  // A path bending away so that the best command is rarely a window corner.
  std::vector<Eigen::Vector2d> path = line({2.025, 2.025}, {2.8, 2.025});
  const std::vector<Eigen::Vector2d> up = line({2.8, 2.025}, {2.8, 3.9});
  path.insert(path.end(), up.begin() + 1, up.end());
  planner.set_plan(path);
  const CostmapGrid local = free_window();
  for (const double v0 : {0.0, 0.05, 0.17, 0.3, 0.45}) {
    for (const double w0 : {-1.3, -0.7, -0.1, 0.0, 0.35, 0.9, 1.0}) {
      INFO("v0 " << v0 << ", w0 " << w0);
      for (const double yaw : {0.0, 1.5, -2.5}) {
        const DwaCommand command = planner.compute(local, {kRobot.x, kRobot.y, yaw}, v0, w0);
        REQUIRE(command.found);
        CHECK(command.v >= params.min_vel_x);
        CHECK(command.v <= params.max_vel_x);
        CHECK(std::abs(command.w) <= params.max_vel_theta);
        // Within one period of acceleration, unless the robot was beyond a limit to begin with.
        if (v0 <= params.max_vel_x) CHECK(std::abs(command.v - v0) <= params.acc_lim_x / params.controller_frequency + 1e-12);
        if (std::abs(w0) <= params.max_vel_theta) {
          CHECK(std::abs(command.w - w0) <= params.acc_lim_theta / params.controller_frequency + 1e-12);
        }
      }
    }
  }
}

TEST_CASE("turning in place toward a heading speeds up, slows down and stops on it") {
  const DwaPlanner planner;
  const CostmapGrid local = free_window();
  Pose2 pose = kRobot;
  double w = 0.0;
  const double target = std::numbers::pi / 2;
  const DwaCommand first = planner.rotate_toward(local, pose, w, target);
  REQUIRE(first.found);
  CHECK(first.v == 0.0);
  CHECK(first.w == Approx(0.2));
  double max_w = 0.0;
  int steps = 0;
  for (; steps < 100 && (std::abs(pose.yaw - target) > 1e-3 || std::abs(w) > 1e-9); ++steps) {
    const DwaCommand command = planner.rotate_toward(local, pose, w, target);
    REQUIRE(command.found);
    CHECK(std::abs(command.w - w) <= 0.2 + 1e-12);
    w = command.w;
    max_w = std::max(max_w, w);
    pose.yaw += w * 0.1;
    CHECK(pose.yaw <= target + 1e-9);  // never overshoots
  }
  CHECK(steps < 40);
  CHECK(max_w == Approx(1.0));
  CHECK(pose.yaw == Approx(target).margin(1e-3));

  SECTION("the short way round across +-pi") {
    const DwaCommand command = planner.rotate_toward(local, {kRobot.x, kRobot.y, 3.0}, 0.0, -3.0);
    CHECK(command.w == Approx(0.2));
  }
  SECTION("not from inside an obstacle or off the costmap") {
    CostmapGrid walled = local;
    walled.set({40, 40}, cost::kLethal);
    CHECK(planner.rotate_toward(walled, kRobot, 0.0, 1.0).reason == "cannot turn in place: the robot's cell is lethal");
    CHECK_FALSE(planner.rotate_toward(local, {-1.0, 0.0, 0.0}, 0.0, 1.0).found);
  }
}

TEST_CASE("within_xy_tolerance compares the distance to the goal") {
  CHECK(within_xy_tolerance({1.0, 1.0, 0.0}, {1.3, 1.4}, 0.5));
  CHECK_FALSE(within_xy_tolerance({1.0, 1.0, 0.0}, {1.3, 1.4}, 0.49));
  CHECK_FALSE(within_xy_tolerance({NAN, 1.0, 0.0}, {1.3, 1.4}, 0.5));
}
