// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA's distance maps: exact chamfer distances around obstacles, no start inside obstacles, and nothing
// through walls.
#include <catch2/catch.hpp>

#include <cmath>

#include "planning_test_support.hpp"
#include "robot/planning/distance_grid.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

TEST_CASE("distances walk around an obstacle without cutting its corners") {
  const CostmapGrid grid = costmap_from_text({".....", ".....", "..#..", ".....", "....."}, 0.1);
  DistanceGrid map;
  map.compute(grid, {static_cast<std::int32_t>(grid.index({0, 2}))});
  // A straight step is 0.1 m, a diagonal one 0.14 m (the 10/14 chamfer).
  CHECK(map.at({0, 2}) == 0.0f);
  CHECK(map.at({1, 2}) == Approx(0.1));
  CHECK(map.at({1, 1}) == Approx(0.14));
  CHECK(map.at({2, 2}) == DistanceGrid::kUnreachable);
  // Past the obstacle: diagonal, two straight steps, then up (no diagonal past its corner).
  CHECK(map.at({3, 2}) == Approx(0.14 + 0.3));
  CHECK(map.at({4, 2}) == Approx(0.28 + 0.2));
  CHECK(map.at({4, 4}) == Approx(0.28 + 0.2));
  CHECK(map.at({-1, 0}) == DistanceGrid::kUnreachable);
  CHECK(map.at({5, 0}) == DistanceGrid::kUnreachable);
}

TEST_CASE("targets inside obstacles are ignored and walled-in cells stay unreachable") {
  const CostmapGrid grid = costmap_from_text({"..###", "..#.#", "..###", "..i..", "....."}, 0.1);
  DistanceGrid map;
  // (2, 1) is inscribed (a person standing on the path): only (3, 1) starts the spread.
  const auto inscribed = static_cast<std::int32_t>(grid.index({2, 1}));
  const auto free_cell = static_cast<std::int32_t>(grid.index({3, 1}));
  map.compute(grid, {inscribed, free_cell, free_cell});
  CHECK(map.at({3, 1}) == 0.0f);
  CHECK(map.at({2, 1}) == DistanceGrid::kUnreachable);
  CHECK(map.at({4, 0}) == Approx(0.14));
  // Under the inscribed cell and up the left side: no diagonal past (2, 1) or the wall at (2, 2).
  CHECK(map.at({0, 4}) == Approx(0.3 + 0.14 + 0.3));
  CHECK(map.at({3, 3}) == DistanceGrid::kUnreachable);  // walled in
  CHECK(map.at({2, 2}) == DistanceGrid::kUnreachable);  // a wall itself

  // With only the inscribed target nothing is reachable (and nothing stale survives from the last call).
  map.compute(grid, {inscribed});
  CHECK(map.at({3, 1}) == DistanceGrid::kUnreachable);
  CHECK(map.at({0, 0}) == DistanceGrid::kUnreachable);
}
