// SPDX-License-Identifier: GPL-2.0-or-later
// LayeredCostmap as the global costmap, the layers together in small rooms: after a run of updates (people
// walking, obstacles appearing and clearing) it equals a brute-force composition of the layers; the dirty
// window is small when little changed; footprint, recovery clears, layer switches and bad input.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "costmap_test_support.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::costmap_test;

TEST_CASE("the global costmap covers the map and inflates its walls by the formula") {
  // 3 x 2.5 m at 0.05 m: border walls and one wall cell at (30, 25).
  const GridMap map = room(60, 50, 0.05, {{30, 25}});
  LayeredCostmap costmap(map, global_costmap_params());
  CHECK(costmap.grid().width == 60);
  CHECK(costmap.grid().height == 50);
  CHECK(costmap.grid().origin_x == Approx(0.0).margin(1e-12));
  CHECK(costmap.grid().origin_y == Approx(0.0).margin(1e-12));
  const CostmapUpdateReport report = costmap.update({1.0, 1.0, 0.0}, nullptr, {});
  CHECK(std::string(report.scan_skipped) == "no scan");
  CHECK(report.window.columns() == 60);  // the first update writes everything
  const CostmapGrid& g = costmap.grid();
  CHECK(g.at({30, 25}) == 254);
  CHECK(g.at({33, 26}) == 253);  // 0.158 m
  CHECK(g.at({34, 25}) == 223);  // 0.2 m
  CHECK(g.at({33, 29}) == 192);  // 0.25 m
  CHECK(g.at({36, 25}) == 165);  // 0.3 m
  CHECK(g.at({37, 25}) == 0);
  CHECK(g.at({0, 10}) == 254);   // the border wall
  CHECK(g.at({6, 10}) == 165);   // 0.3 m from it
  CHECK(count_differences(g, brute_force(costmap, map, {})) == 0);
}

TEST_CASE("after a run of updates the global costmap equals the brute-force composition of its layers") {
  // 5 x 4 m. Only a few beams carry a range (NaN beams are skipped), so each update's dirty window is a
  // small part of the map and its edges fall among old marks and costs: a window too small or a layer
  // that forgets what it wrote last time shows up as a difference.
  const GridMap map = room(100, 80, 0.05, {{50, 40}, {51, 40}, {20, 60}});
  LayeredCostmap costmap(map, global_costmap_params());
  std::vector<SeenPerson> people;
  for (int step = 0; step < 14; ++step) {
    INFO("step " << step);
    // The robot creeps along x; one person walks across the room past the marks, another stands from
    // step 4 on; ahead an obstacle moves away and is then gone; to the left one stays.
    const Pose2 robot{1.01 + 0.02 * step, 1.51, 0.0};
    people = {person_at(4.7 - 0.6 * step, 1.9 + 0.03 * step, -1.3, 0.2)};  // steps beyond the inflation reach
    if (step >= 4) people.push_back(person_at(4.025, 3.025, 0.0, 0.0));
    std::vector<float> ranges(36, std::numeric_limits<float>::quiet_NaN());
    ranges[0] = step < 9 ? static_cast<float>(0.8 + 0.1 * step) : 8.0f;
    ranges[9] = 0.7f;
    ranges[30] = step % 3 == 0 ? 1.0f : 8.0f;
    const LaserScan s = scan(0.0, 2.0 * std::numbers::pi / 36.0, ranges);
    const CostmapUpdateReport report = costmap.update(robot, &s, people);
    CHECK(report.scan_used);
    CHECK(report.people_used == static_cast<int>(people.size()));
    if (step > 0) CHECK(report.window.columns() * report.window.rows() < 100 * 80);
    CHECK(count_differences(costmap.grid(), brute_force(costmap, map, people)) == 0);
  }
  CHECK(marks_of(costmap).mark_count() > 0);
  // The social grid holds the people's costs only.
  const CostmapGrid& social = costmap.social();
  CHECK(social.width == costmap.grid().width);
  CHECK(social.at_world(4.025, 3.025) == 77);
  CHECK(social.at_world(0.01, 0.01) == 0);  // a wall corner: lethal in the master, nothing social
  CHECK(costmap.grid().at_world(0.01, 0.01) == 254);
}

TEST_CASE("the dirty window covers only what changed") {
  const GridMap map = room(200, 200, 0.05);  // 10 x 10 m
  LayeredCostmap costmap(map, global_costmap_params());
  const Pose2 robot{5.0, 5.0, 0.0};
  // People stand on cell centres here, so the cell under them reads the full amplitude.
  costmap.update(robot, nullptr, {});
  CostmapUpdateReport report = costmap.update(robot, nullptr, {});
  CHECK(report.window.empty());  // nothing new: nothing rewritten
  // The person steps 0.5 m: the window covers the cells whose centres lie in the old and new cutoff
  // circles (radius sqrt(2 * 0.25 * ln 7.7) = 1.0104 m), grown by the inflation's 6 cells; x from 1.0146
  // (first centre 1.025, cell 20) to 3.5354 (last centre 3.525, cell 70).
  const std::vector<SeenPerson> one{person_at(2.025, 2.025)};
  const std::vector<SeenPerson> moved{person_at(2.525, 2.025)};
  costmap.update(robot, nullptr, one);
  CHECK(costmap.grid().at_world(2.025, 2.025) == 77);
  report = costmap.update(robot, nullptr, moved);
  CHECK(report.window.min_col == 20 - 6);
  CHECK(report.window.max_col == 70 + 6);
  CHECK_FALSE(report.window.contains(costmap.grid().cell_of(5.0, 5.0)));
  CHECK(costmap.grid().at_world(2.025, 2.025) == 46);  // 77 exp(-0.5^2 / 0.5)
  CHECK(costmap.grid().at_world(2.525, 2.025) == 77);
  // The person leaves the robot's view: their costs go (the window holds their last circle).
  report = costmap.update(robot, nullptr, {});
  CHECK(report.window.min_col == 30 - 6);
  CHECK(costmap.grid().at_world(2.525, 2.025) == 0);
  // A scan: the window spans only the cell the scan marked, plus the reach.
  const LaserScan s = scan(0.0, 0.0, {1.0f});
  report = costmap.update({5.01, 5.01, 0.0}, &s, {});
  CHECK(report.window.columns() == 13);
  CHECK(report.window.rows() == 13);
  CHECK(report.window.contains(costmap.grid().cell_of(6.01, 5.01)));
  CHECK(costmap.grid().at_world(6.01, 5.01) == 254);
}

TEST_CASE("the robot's footprint is never marked, and the scan's marks reach the master with inflation") {
  const GridMap map = room(60, 60, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  // Returns 0.1 m and 0.6 m ahead (range_min lowered so the near one counts).
  const Pose2 robot{1.01, 1.51, 0.0};
  const LaserScan near = scan(0.0, std::numbers::pi, {0.1f, 0.6f}, 0.05);
  costmap.update(robot, &near, {});
  CHECK_FALSE(marks_of(costmap).is_marked_at(1.11, 1.51));
  CHECK(costmap.grid().at_world(1.11, 1.51) == 0);
  CHECK(marks_of(costmap).is_marked_at(0.41, 1.51));
  CHECK(costmap.grid().at_world(0.41, 1.51) == 254);
  CHECK(costmap.grid().at_world(0.61, 1.51) == 223);  // 4 cells on
  // Driving onto an old mark clears it too.
  costmap.update({0.41, 1.51, 0.0}, nullptr, {});
  CHECK_FALSE(marks_of(costmap).is_marked_at(0.41, 1.51));
  CHECK(costmap.grid().at_world(0.41, 1.51) == 0);
}

TEST_CASE("clearing the obstacles beyond a radius keeps the near marks and rewrites the master at once") {
  const GridMap map = room(100, 100, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  const Pose2 robot{2.51, 2.51, 0.0};
  const LaserScan s = scan(0.0, std::numbers::pi / 2, {0.5f, 1.5f});
  costmap.update(robot, &s, {});
  REQUIRE(costmap.grid().at_world(3.01, 2.51) == 254);
  REQUIRE(costmap.grid().at_world(2.51, 4.01) == 254);
  CHECK(costmap.clear_obstacles_beyond({2.51, 2.51}, 1.0) == 1);
  CHECK(costmap.grid().at_world(3.01, 2.51) == 254);
  CHECK(costmap.grid().at_world(2.51, 4.01) == 0);
  CHECK(costmap.grid().at_world(2.51, 3.91) == 0);  // its inflation went with it
  costmap.clear_obstacles();
  CHECK(costmap.grid().at_world(3.01, 2.51) == 0);
  CHECK(marks_of(costmap).mark_count() == 0);
}

TEST_CASE("bad input: an empty scan is used and marks nothing") {
  const GridMap map = room(40, 40, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  const LaserScan empty = scan(0.0, 0.0, {});
  const CostmapUpdateReport report = costmap.update({1.0, 1.0, 0.0}, &empty, {});
  CHECK(report.scan_used);
  CHECK(marks_of(costmap).mark_count() == 0);
}

TEST_CASE("bad input: a scan whose angles are not finite is skipped, saying so") {
  const GridMap map = room(40, 40, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  LaserScan bad = scan(0.0, 0.0, {0.5f});
  bad.angle_min = kNaN;
  const CostmapUpdateReport report = costmap.update({1.0, 1.0, 0.0}, &bad, {});
  CHECK_FALSE(report.scan_used);
  CHECK(std::string(report.scan_skipped) == "scan angles are not finite");
  CHECK(marks_of(costmap).mark_count() == 0);
}

TEST_CASE("bad input: a NaN pose and NaN people crash nothing, and the person with a position is drawn") {
  const GridMap map = room(40, 40, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  const LaserScan empty = scan(0.0, 0.0, {});
  const std::vector<SeenPerson> people{person_at(kNaN, 1.0), person_at(1.0, 1.5, kNaN, 0.0)};
  const CostmapUpdateReport report = costmap.update({kNaN, kNaN, kNaN}, &empty, people);
  CHECK(std::string(report.scan_skipped) == "robot pose is not finite");
  CHECK(report.people_used == 1);
  CHECK(costmap.grid().at_world(1.0, 1.5) == 76);  // 77 exp(-(0.025^2 + 0.025^2) / 0.5) at the cell's centre
}

TEST_CASE("bad input: clearing obstacles beyond a NaN centre drops nothing") {
  const GridMap map = room(40, 40, 0.05);
  LayeredCostmap costmap(map, global_costmap_params());
  const LaserScan one_return = scan(0.0, 0.0, {0.5f});
  costmap.update({0.51, 1.01, 0.0}, &one_return, {});
  REQUIRE(marks_of(costmap).mark_count() == 1);
  CHECK(costmap.clear_obstacles_beyond({kNaN, 0.0}, 1.0) == 0);
  CHECK(marks_of(costmap).mark_count() == 1);
  CHECK(costmap.grid().at_world(1.01, 1.01) == 254);
}

TEST_CASE("layers can be switched off") {
  const GridMap map = room(60, 60, 0.05, {{20, 20}});
  const std::vector<SeenPerson> people{person_at(2.425, 2.425)};
  const LaserScan s = scan(0.0, 0.0, {0.5f});
  const Pose2 robot{0.51, 0.51, 0.0};

  CostmapParams no_social = global_costmap_params();
  no_social.use_proxemic_layer = false;
  LayeredCostmap a(map, no_social);
  a.update(robot, &s, people);
  CHECK(a.grid().at_world(2.425, 2.425) == 0);
  CHECK(std::all_of(a.social().costs.begin(), a.social().costs.end(), [](std::uint8_t c) { return c == 0; }));

  CostmapParams no_static = global_costmap_params();
  no_static.use_static_layer = false;
  LayeredCostmap b(map, no_static);
  b.update(robot, &s, people);
  CHECK(b.grid().at({20, 20}) == 0);   // the wall cell: not in this costmap
  CHECK(b.grid().at({0, 5}) == 0);
  CHECK(b.grid().at_world(1.01, 0.51) == 254);  // the scan's mark is
  CHECK(b.grid().at_world(1.26, 0.51) == 192);  // its inflation too: 5 cells on
  CHECK(b.grid().at_world(2.425, 2.425) == 77);  // and the person

  CostmapParams no_inflation = global_costmap_params();
  no_inflation.use_inflation_layer = false;
  LayeredCostmap c(map, no_inflation);
  c.update(robot, &s, {});
  CHECK(c.grid().at({20, 20}) == 254);
  CHECK(c.grid().at({21, 20}) == 0);
  CHECK(c.grid().at_world(1.01, 0.51) == 254);
  CHECK(c.grid().at_world(1.06, 0.51) == 0);

  CostmapParams no_obstacles = global_costmap_params();
  no_obstacles.use_obstacle_layer = false;
  LayeredCostmap d(map, no_obstacles);
  CHECK(std::string(d.update(robot, &s, {}).scan_skipped) == "obstacle layer off");
  CHECK(d.obstacle_layer() == nullptr);
  CHECK(d.grid().at_world(1.01, 0.51) == 0);
  CHECK(d.clear_obstacles_beyond({0.0, 0.0}, 1.0) == 0);
}

TEST_CASE("out-of-range parameters are refused with the field's name") {
  const GridMap map = room(10, 10, 0.05);
  CostmapParams p;
  p.resolution = 0.0;
  CHECK_THROWS_WITH(LayeredCostmap(map, p), Catch::Contains("resolution"));
  p = CostmapParams{};
  p.proxemic.covariance = 0.0;
  CHECK_THROWS_WITH(LayeredCostmap(map, p), Catch::Contains("covariance"));
  p = CostmapParams{};
  p.inflation.inflation_radius = kNaN;
  CHECK_THROWS_WITH(LayeredCostmap(map, p), Catch::Contains("inflation_radius"));
  CHECK_NOTHROW(LayeredCostmap(map, local_costmap_params()));
}
