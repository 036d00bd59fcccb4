// SPDX-License-Identifier: GPL-2.0-or-later
// The global planner on tiny hand-made costmaps: shortest paths checked against a brute-force Dijkstra,
// cheaper detours, no corner cutting, clean failures with reasons, the goal tolerance, starting inside
// inflation, unknown space, and the straightened path.
#include <catch2/catch.hpp>

#include <cmath>

#include "planning_test_support.hpp"
#include "robot/planning/global_planner.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

constexpr double kRes = 0.1;

// World centre of the cell in text column `col`, text row `text_row` (0 = top line).
Eigen::Vector2d at_text(const CostmapGrid& grid, int col, int text_row) {
  return grid.cell_centre({col, grid.height - 1 - text_row});
}

double path_length(const std::vector<Eigen::Vector2d>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

// The grid path is 8-connected, never enters a cell at or above 253 (the start excepted), and every
// diagonal step has both cells beside it passable.
void check_grid_path(const CostmapGrid& grid, const GlobalPlan& plan) {
  REQUIRE(plan.ok);
  REQUIRE(plan.path.size() >= 2);
  for (std::size_t i = 1; i < plan.path.size(); ++i) {
    const Cell a = grid.cell_of(plan.path[i - 1].x(), plan.path[i - 1].y());
    const Cell b = grid.cell_of(plan.path[i].x(), plan.path[i].y());
    INFO("step " << i << " from (" << a.col << ", " << a.row << ") to (" << b.col << ", " << b.row << ")");
    CHECK(std::max(std::abs(a.col - b.col), std::abs(a.row - b.row)) == 1);
    CHECK(grid.at(b) < cost::kInscribed);
    if (a.col != b.col && a.row != b.row) {
      CHECK(grid.at({b.col, a.row}) < cost::kInscribed);
      CHECK(grid.at({a.col, b.row}) < cost::kInscribed);
    }
  }
}

}  // namespace

TEST_CASE("in free space the path is the straight row of cells") {
  const CostmapGrid grid = CostmapGrid::sized(10, 5, kRes, 0.0, 0.0);
  const GlobalPlan plan = plan_path(grid, at_text(grid, 1, 2), at_text(grid, 8, 2));
  check_grid_path(grid, plan);
  CHECK(plan.reason.empty());
  CHECK(plan.path.size() == 8);
  CHECK(plan.cost == Approx(7 * 50.0));
  for (const Eigen::Vector2d& p : plan.path) CHECK(p.y() == Approx(0.25));
  CHECK(plan.path.front() == at_text(grid, 1, 2));
  CHECK(plan.path.back() == at_text(grid, 8, 2));
}

TEST_CASE("A* finds the brute-force shortest cost and length on hand-made grids") {
  struct Case {
    const char* name;
    CostmapGrid grid;
    Cell start;  // text column, text row
    Cell goal;
    bool uniform;  // all passable cells free: cost = 50 x length in cells
  };
  const Case cases[] = {
      {"wall with a gap",
       costmap_from_text({"..........", "....#.....", "....#.....", "....#.....", "..........", "....#.....",
                          "....#....."},
                         kRes),
       {1, 3}, {8, 3}, true},
      {"maze",
       costmap_from_text({"###########", "#.....#...#", "#.###.#.#.#", "#.#...#.#.#", "#.#.#####.#", "#.#.......#",
                          "#.#######.#", "#.........#", "###########"},
                         kRes),
       {1, 1}, {7, 1}, true},
      {"graded costs",
       costmap_from_text({"..........", ".1234#....", ".5#69#.2..", ".7#..#.3..", ".9..i4.4..", "....8....."},
                         kRes),
       {0, 5}, {9, 0}, false},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const Eigen::Vector2d start = at_text(c.grid, c.start.col, c.start.row);
    const Eigen::Vector2d goal = at_text(c.grid, c.goal.col, c.goal.row);
    const GlobalPlan plan = plan_path(c.grid, start, goal);
    check_grid_path(c.grid, plan);
    const double best = brute_force_cost(c.grid, c.grid.cell_of(start.x(), start.y()), c.grid.cell_of(goal.x(), goal.y()));
    CHECK(plan.cost == Approx(best).epsilon(1e-9));
    if (c.uniform) CHECK(path_length(plan.path) * 50.0 / kRes == Approx(best).epsilon(1e-9));
  }
}

TEST_CASE("a costly band is walked around when the costs say so, crossed straight when it is free") {
  // A 7-cell band of cost 225 (a step costs 252) on the bottom row between start and goal.
  const CostmapGrid banded = costmap_from_text({"...........", "...........", "..9999999.."}, kRes);
  const Eigen::Vector2d start = at_text(banded, 0, 2);
  const Eigen::Vector2d goal = at_text(banded, 10, 2);
  const GlobalPlan detour = plan_path(banded, start, goal);
  check_grid_path(banded, detour);
  // Up one row diagonally, eight cells along, down diagonally: 2 x 50 sqrt 2 + 8 x 50; straight would be 1914.
  CHECK(detour.cost == Approx(100.0 * std::sqrt(2.0) + 400.0));
  for (std::size_t i = 1; i + 1 < detour.path.size(); ++i) CHECK(banded.at_world(detour.path[i].x(), detour.path[i].y()) == 0);

  const CostmapGrid free_grid = costmap_from_text({"...........", "...........", "..........."}, kRes);
  const GlobalPlan straight = plan_path(free_grid, start, goal);
  check_grid_path(free_grid, straight);
  CHECK(straight.cost == Approx(500.0));
  for (const Eigen::Vector2d& p : straight.path) CHECK(p.y() == Approx(0.05));
}

TEST_CASE("no diagonal step slips past a blocked corner") {
  // (1, 1) and (2, 2) touch diagonally between two walls; going around costs six straight steps.
  const CostmapGrid grid = costmap_from_text({"....", ".#..", "..#.", "...."}, kRes);
  const Eigen::Vector2d start = at_text(grid, 1, 2);
  const Eigen::Vector2d goal = at_text(grid, 2, 1);
  const GlobalPlan plan = plan_path(grid, start, goal);
  check_grid_path(grid, plan);
  CHECK(plan.cost == Approx(300.0));
  CHECK(brute_force_cost(grid, grid.cell_of(start.x(), start.y()), grid.cell_of(goal.x(), goal.y())) == Approx(300.0));
}

TEST_CASE("Dijkstra and A* give equal costs, and A* closes fewer cells") {
  const CostmapGrid grid = costmap_from_text(
      {"....................", ".....#..............", ".....#....3333......", ".....#....3##3......", ".....#....3333......",
       ".....#..............", "...................."},
      kRes);
  GlobalPlannerParams dijkstra_params;
  dijkstra_params.use_dijkstra = true;
  const Eigen::Vector2d start = at_text(grid, 1, 3);
  const Eigen::Vector2d goal = at_text(grid, 18, 3);
  const GlobalPlan astar = plan_path(grid, start, goal);
  const GlobalPlan dijkstra = plan_path(grid, start, goal, dijkstra_params);
  check_grid_path(grid, astar);
  check_grid_path(grid, dijkstra);
  CHECK(astar.cost == Approx(dijkstra.cost).epsilon(1e-9));
  CHECK(astar.cost == Approx(brute_force_cost(grid, grid.cell_of(start.x(), start.y()), grid.cell_of(goal.x(), goal.y()))));
  CHECK(astar.expanded < dijkstra.expanded);
}

TEST_CASE("failures come with reasons") {
  const CostmapGrid grid = costmap_from_text({"......", ".####.", ".#..#.", ".####.", "......"}, kRes);
  const Eigen::Vector2d outside = at_text(grid, 0, 4);
  GlobalPlanner planner;

  SECTION("a goal walled in: every reachable cell searched") {
    const GlobalPlan plan = planner.plan(grid, outside, at_text(grid, 2, 2));
    CHECK_FALSE(plan.ok);
    CHECK(plan.path.empty());
    // 30 cells, 10 walls, 2 walled in: 18 reachable.
    CHECK(plan.reason == "goal unreachable: searched 18 cells");
    CHECK(plan.expanded == 18);
  }
  SECTION("start or goal off the grid") {
    CHECK(planner.plan(grid, {-1.0, 0.5}, outside).reason ==
          "start (-1.00, 0.50) is off the costmap (x 0.00..0.60, y 0.00..0.50 m)");
    CHECK(planner.plan(grid, outside, {0.3, 0.55}).reason ==
          "goal (0.30, 0.55) is off the costmap (x 0.00..0.60, y 0.00..0.50 m)");
  }
  SECTION("goal in a wall") {
    const GlobalPlan plan = planner.plan(grid, outside, at_text(grid, 1, 1));
    CHECK_FALSE(plan.ok);
    CHECK(plan.reason == "goal (0.15, 0.35) is in an obstacle (cost 254)");
  }
  SECTION("non-finite points, an empty grid and bad parameters") {
    CHECK(planner.plan(grid, {std::nan(""), 0.0}, outside).reason == "start is not a finite point");
    CHECK(planner.plan(grid, outside, {0.1, INFINITY}).reason == "goal is not a finite point");
    CHECK_FALSE(planner.plan(CostmapGrid{}, outside, outside).ok);
    GlobalPlannerParams bad;
    bad.neutral_cost = 0.0;
    CHECK(plan_path(grid, outside, outside, bad).reason.rfind("bad planner parameters", 0) == 0);
  }
  SECTION("start and goal in one cell") {
    const GlobalPlan plan = planner.plan(grid, {0.01, 0.41}, {0.09, 0.49});
    CHECK(plan.ok);
    CHECK(plan.path == std::vector<Eigen::Vector2d>{{0.01, 0.41}, {0.09, 0.49}});
    CHECK(plan.cost == 0.0);
  }
}

TEST_CASE("default_tolerance moves a blocked goal to the nearest passable cell") {
  const CostmapGrid grid = costmap_from_text({"......", "...##.", "...##.", "......"}, kRes);
  const Eigen::Vector2d start = at_text(grid, 0, 1);
  // In the wall's left column, 0.09 m from the free cell to its left and 0.1005 m from the one above.
  const Eigen::Vector2d goal = at_text(grid, 3, 1) - Eigen::Vector2d(0.01, 0.0);
  CHECK(plan_path(grid, start, goal).reason == "goal (0.34, 0.25) is in an obstacle (cost 254)");
  GlobalPlannerParams params;
  params.default_tolerance = 0.095;
  const GlobalPlan plan = plan_path(grid, start, goal, params);
  REQUIRE(plan.ok);
  CHECK(plan.path.back() == at_text(grid, 2, 1));
  CHECK(plan.cost == Approx(100.0));
  params.default_tolerance = 0.05;
  CHECK(plan_path(grid, start, goal, params).reason ==
        "goal (0.34, 0.25) is in an obstacle (cost 254) and no passable cell lies within 0.05 m");
}

TEST_CASE("a robot pushed into inflation plans its way out, but only from where it stands") {
  const CostmapGrid grid = costmap_from_text({"........", ".iii....", ".iii....", ".iii....", "........"}, kRes);
  const Eigen::Vector2d start = at_text(grid, 2, 2);
  SECTION("out through one inscribed cell, then free ones") {
    const GlobalPlan plan = plan_path(grid, start, at_text(grid, 7, 2));
    REQUIRE(plan.ok);
    CHECK(plan.cost == Approx(252.0 + 4 * 50.0));
    CHECK(plan.path.front() == start);
  }
  SECTION("inflation elsewhere still blocks") {
    const CostmapGrid walled = costmap_from_text({"..iii.i.", ".iii..i.", ".iii..i.", ".iii..i.", "......i."}, kRes);
    const GlobalPlan plan = plan_path(walled, start, at_text(walled, 7, 2));
    CHECK_FALSE(plan.ok);
    CHECK(plan.reason.find("goal unreachable: searched") == 0);
    CHECK(plan.reason.find("(the start (0.25, 0.25) is in an obstacle, cost 253)") != std::string::npos);
  }
  SECTION("a start inside a wall with nothing but wall around cannot leave") {
    const CostmapGrid wall = costmap_from_text({"......", ".###..", ".###..", ".###..", "......"}, kRes);
    const GlobalPlan plan = plan_path(wall, at_text(wall, 2, 2), at_text(wall, 5, 2));
    CHECK(plan.reason == "goal unreachable: searched 1 cells (the start (0.25, 0.25) is in an obstacle, cost 254)");
  }
}

TEST_CASE("unknown space is passable only when allowed, at the highest cost") {
  const CostmapGrid grid = costmap_from_text({"..?..", "..?..", "..?.."}, kRes);
  const Eigen::Vector2d start = at_text(grid, 0, 1);
  const Eigen::Vector2d goal = at_text(grid, 4, 1);
  CHECK(plan_path(grid, start, goal).reason == "goal unreachable: searched 6 cells");
  GlobalPlannerParams params;
  params.allow_unknown = true;
  const GlobalPlan plan = plan_path(grid, start, goal, params);
  REQUIRE(plan.ok);
  CHECK(plan.cost == Approx(3 * 50.0 + 252.0));
}

TEST_CASE("the planner reuses its buffers across grids of different sizes") {
  GlobalPlanner planner;
  const CostmapGrid small = costmap_from_text({".....", ".#...", "....."}, kRes);
  const CostmapGrid large = CostmapGrid::sized(30, 20, kRes, -1.0, -1.0);
  const GlobalPlan first = planner.plan(small, at_text(small, 0, 1), at_text(small, 4, 1));
  const GlobalPlan second = planner.plan(large, {-0.95, -0.95}, {1.95, 0.95});
  const GlobalPlan third = planner.plan(small, at_text(small, 0, 1), at_text(small, 4, 1));
  REQUIRE(first.ok);
  REQUIRE(second.ok);
  CHECK(second.cost == Approx(brute_force_cost(large, {0, 0}, {29, 19})));
  CHECK(third.path == first.path);
  CHECK(third.cost == first.cost);
}
