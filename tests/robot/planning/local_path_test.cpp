// SPDX-License-Identifier: GPL-2.0-or-later
// Cutting the global path to the local costmap: from the point nearest the robot, up to where it leaves the
// window, without jumping to a later stretch that happens to pass nearer.
#include <catch2/catch.hpp>

#include "robot/planning/local_path.hpp"

using namespace rfbsim::sim;

namespace {

// Points every `step` m from a to b, b included, a included when `with_a`.
void add_line(std::vector<Eigen::Vector2d>& path, Eigen::Vector2d a, Eigen::Vector2d b, double step, bool with_a) {
  const int pieces = static_cast<int>(std::lround((b - a).norm() / step));
  for (int i = with_a ? 0 : 1; i <= pieces; ++i) path.push_back(a + (b - a) * (static_cast<double>(i) / pieces));
}

}  // namespace

TEST_CASE("the local path runs from the point nearest the robot to where the path leaves the window") {
  const CostmapGrid grid = CostmapGrid::sized(20, 20, 0.1, 0.0, 0.0);  // 2 m x 2 m
  std::vector<Eigen::Vector2d> path;
  add_line(path, {-1.0, 1.0}, {3.0, 1.0}, 0.5, true);  // (-1, 1), (-0.5, 1), ... (3, 1)
  std::vector<std::int32_t> cells;
  const LocalPathCut cut = cut_local_path(path, 0, 10.0, grid, {1.02, 1.2}, cells);
  REQUIRE(cut.ok);
  CHECK(cut.nearest == 4);  // (1, 1)
  CHECK_FALSE(cut.ends_at_goal);
  CHECK(cut.local_goal.x() == Approx(1.95));
  CHECK(cut.local_goal.y() == Approx(1.0));
  // Cells (10, 10) .. (19, 10), each once.
  REQUIRE(cells.size() == 10);
  for (std::size_t i = 0; i < cells.size(); ++i) CHECK(cells[i] == static_cast<std::int32_t>(grid.index({10 + static_cast<int>(i), 10})));
}

TEST_CASE("a path ending inside the window ends at its goal") {
  const CostmapGrid grid = CostmapGrid::sized(20, 20, 0.1, 0.0, 0.0);
  const std::vector<Eigen::Vector2d> path{{0.25, 0.25}, {0.25, 0.55}};
  std::vector<std::int32_t> cells;
  const LocalPathCut cut = cut_local_path(path, 0, 10.0, grid, {0.2, 0.2}, cells);
  REQUIRE(cut.ok);
  CHECK(cut.ends_at_goal);
  CHECK(cut.local_goal == Eigen::Vector2d(0.25, 0.55));
  CHECK(cells.size() == 4);  // rows 2..5 of column 2
}

TEST_CASE("the nearest point is searched only a horizon ahead of the last progress") {
  // Out along y = 0.5 and back along y = 0.7; the robot at the start stands nearer the way back.
  const CostmapGrid grid = CostmapGrid::sized(20, 20, 0.1, 0.0, 0.0);
  std::vector<Eigen::Vector2d> path;
  add_line(path, {0.1, 0.5}, {1.5, 0.5}, 0.1, true);   // indices 0..14
  add_line(path, {1.5, 0.5}, {1.5, 0.7}, 0.1, false);  // 15..16
  add_line(path, {1.5, 0.7}, {0.1, 0.7}, 0.1, false);  // 17..30
  std::vector<std::int32_t> cells;
  LocalPathCut cut = cut_local_path(path, 0, 1.0, grid, {0.2, 0.62}, cells);
  REQUIRE(cut.ok);
  CHECK(cut.nearest == 1);
  CHECK(cut.ends_at_goal);
  cut = cut_local_path(path, 0, 10.0, grid, {0.2, 0.62}, cells);
  CHECK(cut.nearest == 29);
}

TEST_CASE("a path away from the window or missing is refused with a reason") {
  const CostmapGrid grid = CostmapGrid::sized(20, 20, 0.1, 0.0, 0.0);
  std::vector<std::int32_t> cells{1, 2, 3};
  LocalPathCut cut = cut_local_path({{5.0, 1.0}, {6.0, 1.0}}, 0, 10.0, grid, {1.0, 1.0}, cells);
  CHECK_FALSE(cut.ok);
  CHECK(cut.reason ==
        "the global path leaves the local costmap at the robot: its nearest point (5.00, 1.00) is 4.00 m away, off the costmap");
  CHECK(cells.empty());
  cut = cut_local_path({}, 0, 10.0, grid, {1.0, 1.0}, cells);
  CHECK(cut.reason == "no global path set");
}
