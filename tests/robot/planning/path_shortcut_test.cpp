// SPDX-License-Identifier: GPL-2.0-or-later
// Path shortcuts: exact segment costs through cells and corners, and straightened paths that are never
// costlier nor nearer to obstacles than the grid path.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "planning_test_support.hpp"
#include "robot/planning/global_planner.hpp"
#include "robot/planning/path_shortcut.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

// global_planner's step costs with the default parameters.
std::array<double, 256> default_step_costs() {
  std::array<double, 256> table{};
  for (std::size_t c = 0; c < 256; ++c) {
    table[c] = c >= 253 ? std::numeric_limits<double>::infinity() : std::min(50.0 + 3.0 * static_cast<double>(c), 252.0);
  }
  return table;
}

// The highest cell cost among the points of a path.
int max_cost_along(const CostmapGrid& grid, const std::vector<Eigen::Vector2d>& path) {
  int worst = 0;
  for (const Eigen::Vector2d& p : path) worst = std::max(worst, static_cast<int>(grid.at_world(p.x(), p.y())));
  return worst;
}

}  // namespace

TEST_CASE("a segment costs the length it runs in each cell times that cell's step cost") {
  const std::array<double, 256> table = default_step_costs();
  int max_cost = -1;
  SECTION("along a row, half of each end cell") {
    const CostmapGrid grid = costmap_from_text({".....", "..4..", "....."}, 0.1);
    CHECK(segment_cost(grid, {0, 1}, {4, 1}, table, max_cost) == Approx(0.5 * 50 + 50 + 252 + 50 + 0.5 * 50));
    CHECK(max_cost == 100);
  }
  SECTION("a shallow diagonal crosses four cells a quarter of its length each") {
    const CostmapGrid grid = costmap_from_text({"...", "...", ".1."}, 0.1);
    CHECK(segment_cost(grid, {0, 0}, {2, 1}, table, max_cost) == Approx(std::sqrt(5.0) * 0.25 * (3 * 50 + 125)));
    CHECK(max_cost == 25);
  }
  SECTION("through exact grid corners, whose side cells must be passable") {
    CostmapGrid grid = costmap_from_text({"...", "...", "..."}, 0.1);
    CHECK(segment_cost(grid, {0, 0}, {2, 2}, table, max_cost) == Approx(2.0 * std::sqrt(2.0) * 50));
    grid.set({1, 0}, cost::kLethal);
    CHECK(std::isinf(segment_cost(grid, {0, 0}, {2, 2}, table, max_cost)));
  }
  SECTION("into an obstacle or off the grid") {
    const CostmapGrid grid = costmap_from_text({"....", "..i.", "...."}, 0.1);
    CHECK(std::isinf(segment_cost(grid, {0, 1}, {3, 1}, table, max_cost)));
    CHECK(std::isinf(segment_cost(grid, {0, 0}, {5, 0}, table, max_cost)));
  }
}

TEST_CASE("a zig-zag grid path in free space becomes one straight leg") {
  const CostmapGrid grid = CostmapGrid::sized(20, 10, 0.1, 0.0, 0.0);
  GlobalPlannerParams params;
  params.simplify_path = true;
  const Eigen::Vector2d start(0.15, 0.15);
  const Eigen::Vector2d goal(1.85, 0.75);
  const GlobalPlan plan = plan_path(grid, start, goal, params);
  REQUIRE(plan.ok);
  CHECK(plan.path.front() == start);
  CHECK(plan.path.back() == goal);
  // Every point on the straight segment, at most one cell length apart.
  const Eigen::Vector2d along = (goal - start).normalized();
  for (std::size_t i = 0; i < plan.path.size(); ++i) {
    const Eigen::Vector2d d = plan.path[i] - start;
    CHECK(std::abs(d.x() * along.y() - d.y() * along.x()) < 1e-9);
    if (i > 0) CHECK((plan.path[i] - plan.path[i - 1]).norm() <= 0.1 + 1e-9);
  }
  // The cost reported is the grid path's: 6 diagonal and 11 straight steps.
  CHECK(plan.cost == Approx(6 * 50 * std::sqrt(2.0) + 11 * 50));
}

TEST_CASE("straightening never brings the path nearer to obstacles") {
  // An inflated pillar between start and goal, and a wall with one door.
  CostmapGrid grid = costmap_from_text({"..............................", "..............................",
                                        "..........#...................", "..........#..........#........",
                                        "..........#..........#........", "..........#..........#........",
                                        "..........#..........#........", "..........#..........#........",
                                        "......................#.......", "..............................",
                                        ".....................#........", ".....................#........"},
                                       0.05);
  inflate(grid, 0.1, 0.4);
  GlobalPlannerParams params;
  const Eigen::Vector2d start = grid.cell_centre({1, 1});
  const Eigen::Vector2d goal = grid.cell_centre({28, 10});
  const GlobalPlan raw = plan_path(grid, start, goal, params);
  params.simplify_path = true;
  const GlobalPlan straight = plan_path(grid, start, goal, params);
  REQUIRE(raw.ok);
  REQUIRE(straight.ok);
  CHECK(straight.cost == raw.cost);
  CHECK(straight.path.front() == raw.path.front());
  CHECK(straight.path.back() == raw.path.back());
  CHECK(max_cost_along(grid, straight.path) <= max_cost_along(grid, raw.path));
  CHECK(path_below(grid, straight.path, cost::kInscribed));
  double raw_length = 0.0;
  double straight_length = 0.0;
  for (std::size_t i = 1; i < raw.path.size(); ++i) raw_length += (raw.path[i] - raw.path[i - 1]).norm();
  for (std::size_t i = 1; i < straight.path.size(); ++i) {
    straight_length += (straight.path[i] - straight.path[i - 1]).norm();
    CHECK((straight.path[i] - straight.path[i - 1]).norm() <= 0.05 + 1e-9);
  }
  CHECK(straight_length < raw_length);
}
