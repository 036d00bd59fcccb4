// SPDX-License-Identifier: GPL-2.0-or-later
// Both planners in a loop: the global planner's path through an inflated L-shaped corridor (and round an
// obstacle that appears), followed by the DWA on a rolling window, the robot driven exactly by its commands.
// It must reach the goal without ever touching an inscribed or lethal cell, and do so the same way every time.
#include <catch2/catch.hpp>

#include <cmath>

#include "planning_test_support.hpp"
#include "robot/planning/dwa_planner.hpp"
#include "robot/planning/global_planner.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

// A 4 m x 4 m map at 0.05 m, solid except an L-shaped corridor 0.8 m wide: along the bottom from x = 0.3 to
// 3.3 (y 0.3..1.1), then up the right from y = 0.3 to 3.7 (x 2.5..3.3); inflated by `inflation` m around an
// inscribed radius of 0.16 m (cost_scaling_factor 3).
CostmapGrid l_corridor(double inflation) {
  CostmapGrid grid = CostmapGrid::sized(80, 80, 0.05, 0.0, 0.0);
  for (int row = 0; row < 80; ++row) {
    for (int col = 0; col < 80; ++col) {
      const Eigen::Vector2d c = grid.cell_centre({col, row});
      const bool bottom = c.x() > 0.3 && c.x() < 3.3 && c.y() > 0.3 && c.y() < 1.1;
      const bool right = c.x() > 2.5 && c.x() < 3.3 && c.y() > 0.3 && c.y() < 3.7;
      if (!bottom && !right) grid.set({col, row}, cost::kLethal);
    }
  }
  inflate(grid, 0.16, inflation);
  return grid;
}

struct Run {
  bool arrived = false;
  int cycles = 0;
  int worst_cost = 0;  // the highest local-costmap cost the robot's centre ever stood on
  std::vector<Pose2> poses;  // at every cycle
};

// Drives from `start` to `goal` as the navigator would: a global plan on `global` (again every
// `replan_every` cycles when that is not 0), the DWA on a 3 m window of `local` around the robot each
// cycle, its command held for 0.1 s and followed exactly (checked every 10 ms); until within 0.15 m of the
// goal or 60 s have passed. The first plan may be made on `first_global` (a map without a new obstacle).
Run drive(const CostmapGrid& first_global, const CostmapGrid& global, const CostmapGrid& local, Pose2 start,
          const Eigen::Vector2d& goal, int replan_every) {
  Run run;
  GlobalPlanner global_planner;
  DwaPlanner dwa;
  const GlobalPlan first = global_planner.plan(first_global, {start.x, start.y}, goal);
  REQUIRE(first.ok);
  dwa.set_plan(first.path);
  Pose2 pose = start;
  double v = 0.0;
  double w = 0.0;
  for (; run.cycles < 600 && !run.arrived; ++run.cycles) {
    run.poses.push_back(pose);
    if (replan_every > 0 && run.cycles > 0 && run.cycles % replan_every == 0) {
      const GlobalPlan plan = global_planner.plan(global, {pose.x, pose.y}, goal);
      REQUIRE(plan.ok);
      dwa.set_plan(plan.path);
    }
    const CostmapGrid window = window_of(local, pose.x, pose.y, 3.0);
    const DwaCommand command = dwa.compute(window, pose, v, w);
    INFO("cycle " << run.cycles << " at (" << pose.x << ", " << pose.y << "): " << command.reason);
    REQUIRE(command.found);
    v = command.v;
    w = command.w;
    for (int k = 0; k < 10; ++k) {
      const double yaw = pose.yaw;
      pose.yaw += w * 0.01;
      if (std::abs(w) < 1e-12) {
        pose.x += v * 0.01 * std::cos(yaw);
        pose.y += v * 0.01 * std::sin(yaw);
      } else {
        pose.x += v / w * (std::sin(pose.yaw) - std::sin(yaw));
        pose.y -= v / w * (std::cos(pose.yaw) - std::cos(yaw));
      }
      run.worst_cost = std::max(run.worst_cost, static_cast<int>(local.at_world(pose.x, pose.y)));
    }
    run.arrived = within_xy_tolerance(pose, goal, 0.15);
  }
  return run;
}

}  // namespace

TEST_CASE("the robot follows an L-shaped path to its end without touching inflation") {
  // Kuri's global costmap inflates 0.3 m; the local one here 0.2 m (a thin graded band past inscribed).
  const CostmapGrid global = l_corridor(0.3);
  const CostmapGrid local = l_corridor(0.2);
  const Pose2 start{0.6, 0.7, 0.0};
  const Eigen::Vector2d goal(2.9, 3.3);
  const Run run = drive(global, global, local, start, goal, 0);
  CHECK(run.arrived);
  CHECK(run.worst_cost < cost::kInscribed);
  // 3.3 m in a straight line at 0.3 m/s would take 110 cycles; the corridor about 5 m.
  CHECK(run.cycles > 110);
  CHECK(run.cycles < 250);

  // The same inputs give the same run, bit for bit.
  const Run again = drive(global, global, local, start, goal, 0);
  REQUIRE(again.poses.size() == run.poses.size());
  bool same = true;
  for (std::size_t i = 0; i < run.poses.size(); ++i) {
    same = same && run.poses[i].x == again.poses[i].x && run.poses[i].y == again.poses[i].y &&
           run.poses[i].yaw == again.poses[i].yaw;
  }
  CHECK(same);
}

TEST_CASE("an obstacle that appears on the path is passed once the global plan goes round it") {
  // A 4 m x 3 m room; a 0.4 m box drops onto the straight path after the first plan. The DWA alone would
  // stall in front of it (the path runs through it); replanning each second, as move_base does, leads round.
  CostmapGrid empty = CostmapGrid::sized(80, 60, 0.05, 0.0, 0.0);
  CostmapGrid boxed = empty;
  for (int row = 26; row < 34; ++row) {
    for (int col = 36; col < 44; ++col) boxed.set({col, row}, cost::kLethal);
  }
  CostmapGrid global = boxed;
  inflate(global, 0.16, 0.3);
  CostmapGrid local = boxed;
  inflate(local, 0.16, 0.2);
  const Run run = drive(empty, global, local, {0.5, 1.525, 0.0}, {3.5, 1.525}, 10);
  CHECK(run.arrived);
  CHECK(run.worst_cost < cost::kInscribed);
  CHECK(run.cycles < 150);
}
