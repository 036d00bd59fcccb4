// SPDX-License-Identifier: GPL-2.0-or-later
// LayeredCostmap as a rolling window: it follows the robot, keeps obstacle marks where they are in the
// world, reads lethal off the map's edge, and equals the brute-force composition of its layers each step.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "costmap_test_support.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::costmap_test;

TEST_CASE("the rolling window follows the robot and keeps obstacle marks in world coordinates") {
  const GridMap map = room(100, 80, 0.1);  // 10 x 8 m at 0.1 m
  LayeredCostmap costmap(map, local_costmap_params());
  REQUIRE(costmap.grid().width == 80);
  REQUIRE(costmap.grid().height == 80);
  const LaserScan s = scan(0.0, 0.0, {1.0f});
  costmap.update({3.01, 4.01, 0.0}, &s, {});
  const CostmapGrid& g = costmap.grid();
  // The robot's cell is the window's middle one.
  CHECK(g.cell_of(3.01, 4.01) == Cell{40, 40});
  CHECK(g.at_world(4.01, 4.01) == 254);
  const Cell before = g.cell_of(4.01, 4.01);
  // 1.5 m on (no new scan): the window moves by 30 cells, the mark stays at its world point.
  costmap.update({4.51, 4.01, 0.0}, nullptr, {});
  CHECK(g.cell_of(4.51, 4.01) == Cell{40, 40});
  CHECK(g.cell_of(4.01, 4.01).col == before.col - 30);
  CHECK(g.at_world(4.01, 4.01) == 254);
  // Far away the mark leaves the window; back again it is still there.
  costmap.update({8.01, 4.01, 0.0}, nullptr, {});
  CHECK(g.at_world(4.01, 4.01, 7) == 7);  // outside the window now
  costmap.update({3.01, 4.01, 0.0}, nullptr, {});
  CHECK(g.at_world(4.01, 4.01) == 254);
  // The local inflation (0.1 m) is 253 up to 2 cells, nothing at 3.
  CHECK(g.at_world(4.11, 4.01) == 253);
  CHECK(g.at_world(4.16, 4.01) == 0);
}

TEST_CASE("a rolling window driven along and off the map equals the brute-force composition each step") {
  const GridMap map = room(60, 40, 0.1, {{30, 20}, {31, 20}, {45, 10}});  // 6 x 4 m at 0.1 m
  for (const double inflation : {0.1, 0.3}) {
    LayeredCostmap costmap(map, local_costmap_params(inflation, 3.0, 2.0));
    REQUIRE(costmap.grid().width == 60);
    REQUIRE(costmap.grid().height == 40);
    for (int step = 0; step < 10; ++step) {
      INFO("inflation " << inflation << ", step " << step);
      const Pose2 robot{0.71 + 0.55 * step, 1.21 + 0.05 * step, 0.2 * step};  // a fifth into a cell
      const std::vector<SeenPerson> people{person_at(4.0 - 0.2 * step, 2.5, -1.0, 0.2)};
      std::vector<float> ranges(24, 8.0f);
      ranges[static_cast<std::size_t>(step % 24)] = 1.2f;
      ranges[3] = step < 5 ? 0.9f : 8.0f;
      const LaserScan s = scan(0.0, 2.0 * std::numbers::pi / 24.0, ranges);
      costmap.update(robot, &s, people);
      CHECK(costmap.grid().cell_of(robot.x, robot.y) == Cell{30, 20});
      CHECK(count_differences(costmap.grid(), brute_force(costmap, map, people)) == 0);
    }
  }
}

TEST_CASE("a rolling window over the map's edge reads lethal beyond the map, and a bad pose leaves it in place") {
  const GridMap map = room(60, 60, 0.1);  // 6 x 6 m
  LayeredCostmap costmap(map, local_costmap_params());
  costmap.update({0.51, 3.01, 0.0}, nullptr, {});
  const CostmapGrid& g = costmap.grid();
  CHECK(g.at_world(-1.0, 3.0) == 254);   // off the map
  CHECK(g.at_world(0.05, 3.0) == 254);   // the border wall
  CHECK(g.at_world(0.51, 3.01) == 0);
  const double origin = g.origin_x;
  const LaserScan s = scan(0.0, 0.0, {1.0f});
  const CostmapUpdateReport report = costmap.update({kNaN, 3.0, 0.0}, &s, {});
  CHECK_FALSE(report.scan_used);
  CHECK(std::string(report.scan_skipped) == "robot pose is not finite");
  CHECK(g.origin_x == origin);
  CHECK(marks_of(costmap).mark_count() == 0);
}
