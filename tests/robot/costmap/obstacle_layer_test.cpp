// SPDX-License-Identifier: GPL-2.0-or-later
// The obstacle layer on a 5 x 5 m frame: marking returns, clearing along later beams, the ranges, the
// footprint, the recovery clears, and bad input.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "costmap_test_support.hpp"
#include "robot/costmap/obstacle_layer.hpp"

using namespace rfbsim::sim;
using costmap_test::kNaN;
using costmap_test::scan;

namespace {

CostmapGrid frame() { return CostmapGrid::sized(100, 100, 0.05, 0.0, 0.0); }

// The robot sits a fifth of a cell into cell (20, 50), so returns at whole multiples of 0.05 m along the
// axes land a fifth into a cell, never on a boundary.
const Pose2 kRobot{1.01, 2.51, 0.0};

// Marks returns at 0.5 m (+x), 1.5 m (+y), 0.9 m (-x) and 2.0 m (-y) from kRobot.
void mark_four_returns_around_robot(ObstacleLayer& layer) {
  layer.add_scan(kRobot, scan(0.0, std::numbers::pi / 2, {0.5f, 1.5f, 0.9f, 2.0f}));
  REQUIRE(layer.mark_count() == 4);
}

}  // namespace

TEST_CASE("a return marks its cell, the cells before it stay free, and the mark persists") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  REQUIRE(layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f})));
  CHECK(layer.mark_count() == 1);
  CHECK(layer.is_marked_at(2.01, 2.51));
  CHECK(layer.marks().at({40, 50}) == cost::kLethal);
  CHECK(layer.marks().at({39, 50}) == cost::kFree);
  // An empty scan changes nothing; the mark stays.
  REQUIRE(layer.add_scan(kRobot, scan(0.0, 0.0, {})));
  CHECK(layer.is_marked_at(2.01, 2.51));
  // The sensor's heading turns the beams: yaw pi/2 and angle_min pi/2 point along -x.
  REQUIRE(layer.add_scan({1.01, 2.51, std::numbers::pi / 2}, scan(std::numbers::pi / 2, 0.0, {0.5f})));
  CHECK(layer.is_marked_at(0.51, 2.51));
  CHECK(layer.mark_count() == 2);
}

TEST_CASE("a later beam through a marked cell clears it, from the same pose or another") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));
  REQUIRE(layer.is_marked_at(2.01, 2.51));
  // The same way, a farther return: the old cell is crossed and cleared, the new one marked.
  layer.add_scan(kRobot, scan(0.0, 0.0, {2.0f}));
  CHECK_FALSE(layer.is_marked_at(2.01, 2.51));
  CHECK(layer.is_marked_at(3.01, 2.51));
  CHECK(layer.mark_count() == 1);
  // From below, looking up (+y) through (3.01, 2.51) to a return 1.5 m farther up.
  layer.add_scan({3.01, 1.51, 0.0}, scan(std::numbers::pi / 2, 0.0, {2.5f}));
  CHECK_FALSE(layer.is_marked_at(3.01, 2.51));
  CHECK(layer.is_marked_at(3.01, 4.01));
}

TEST_CASE("a beam with no return (range_max) clears along the ray and marks nothing") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));
  REQUIRE(layer.mark_count() == 1);
  layer.add_scan(kRobot, scan(0.0, 0.0, {8.0f}));
  CHECK(layer.mark_count() == 0);
  // Infinity reads the same.
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));
  layer.add_scan(kRobot, scan(0.0, 0.0, {std::numeric_limits<float>::infinity()}));
  CHECK(layer.mark_count() == 0);
}

TEST_CASE("only returns within obstacle_range mark, and beams clear only up to raytrace_range") {
  ObstacleLayer defaults(ObstacleLayerParams{}, frame(), 0.16);  // 2.5 m, 3.0 m
  defaults.add_scan(kRobot, scan(0.0, 0.0, {2.45f}));
  CHECK(defaults.is_marked_at(3.46, 2.51));
  defaults.add_scan(kRobot, scan(std::numbers::pi / 2, 0.0, {2.0f}));  // another direction: leaves it
  CHECK(defaults.mark_count() == 2);
  defaults.add_scan(kRobot, scan(0.0, 0.0, {2.7f}));  // beyond 2.5 m: clears the way, marks nothing
  CHECK(defaults.mark_count() == 1);
  CHECK_FALSE(defaults.is_marked_at(3.71, 2.51));

  // With a long obstacle_range, make marks at 2.8 m and 3.2 m ahead, then a return at 4 m clears up to
  // 3.0 m only: the 2.8 m mark goes, the 3.2 m one stays.
  ObstacleLayer layer(ObstacleLayerParams{5.0, 3.0}, frame(), 0.16);
  layer.add_scan(kRobot, scan(0.0, 0.0, {3.2f}));
  layer.add_scan(kRobot, scan(0.0, 0.0, {2.8f}));
  REQUIRE(layer.is_marked_at(4.21, 2.51));
  REQUIRE(layer.is_marked_at(3.81, 2.51));
  layer.add_scan(kRobot, scan(0.0, 0.0, {4.0f}));
  CHECK_FALSE(layer.is_marked_at(3.81, 2.51));
  CHECK(layer.is_marked_at(4.21, 2.51));
}

TEST_CASE("a slanted beam clears the cells it crosses and not their neighbours off the line") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  // From the centre of cell (20, 20) along slope 1/2, the ray passes through the centre of cell (30, 25);
  // cell (30, 26) above it spans y 1.30..1.35 where the ray is at y 1.2625..1.2875: not crossed.
  // Mark both from above, looking down: first the lower (0.75 m), then the upper (0.70 m, stopping short).
  const Pose2 above{1.525, 2.025, 0.0};
  layer.add_scan(above, scan(-std::numbers::pi / 2, 0.0, {0.75f}));
  layer.add_scan(above, scan(-std::numbers::pi / 2, 0.0, {0.70f}));
  REQUIRE(layer.marks().at({30, 25}) == cost::kLethal);
  REQUIRE(layer.marks().at({30, 26}) == cost::kLethal);
  layer.add_scan({1.025, 1.025, 0.0}, scan(std::atan2(1.0, 2.0), 0.0, {1.5f}));
  CHECK(layer.marks().at({30, 25}) == cost::kFree);
  CHECK(layer.marks().at({30, 26}) == cost::kLethal);
}

TEST_CASE("within one scan all beams clear first, so a beam through another beam's hit keeps it") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  // Beam 0 ends in (40, 50); beam 1, 0.002 rad to the left, passes through that cell to a return 1 m on.
  layer.add_scan(kRobot, scan(0.0, 0.002, {1.0f, 2.0f}));
  CHECK(layer.marks().at({40, 50}) == cost::kLethal);
  CHECK(layer.is_marked_at(3.01, 2.51 + 2.0 * std::sin(0.002)));
  CHECK(layer.mark_count() == 2);
}

TEST_CASE("the footprint is cleared of marks, the rest is kept") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  // range_min lowered so that a return 0.1 m away counts; another 0.3 m away.
  layer.add_scan(kRobot, scan(0.0, std::numbers::pi, {0.1f, 0.3f}, 0.05));
  REQUIRE(layer.is_marked_at(1.11, 2.51));
  REQUIRE(layer.is_marked_at(0.71, 2.51));
  layer.clear_footprint(kRobot.x, kRobot.y);
  CHECK_FALSE(layer.is_marked_at(1.11, 2.51));
  CHECK(layer.is_marked_at(0.71, 2.51));
  CHECK(layer.mark_count() == 1);
  layer.clear_footprint(kNaN, 0.0);  // nothing, no crash
  CHECK(layer.mark_count() == 1);
}

TEST_CASE("clear_beyond keeps near marks and drops far ones") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  mark_four_returns_around_robot(layer);
  CHECK(layer.clear_beyond({kRobot.x, kRobot.y}, 1.0) == 2);
  CHECK(layer.is_marked_at(1.51, 2.51));
  CHECK(layer.is_marked_at(0.11, 2.51));
  CHECK_FALSE(layer.is_marked_at(1.01, 4.01));
  CHECK_FALSE(layer.is_marked_at(1.01, 0.51));
  CHECK(layer.mark_count() == 2);
}

TEST_CASE("clear_beyond drops nothing around a NaN centre and everything at a negative distance") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  mark_four_returns_around_robot(layer);
  CHECK(layer.clear_beyond({kNaN, 0.0}, 1.0) == 0);
  CHECK(layer.mark_count() == 4);
  CHECK(layer.clear_beyond({kRobot.x, kRobot.y}, -1.0) == 4);  // a negative distance: everything
  CHECK(layer.mark_count() == 0);
}

TEST_CASE("clear_all drops all marks") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  mark_four_returns_around_robot(layer);
  layer.clear_all();
  CHECK(layer.mark_count() == 0);
  CHECK(std::all_of(layer.marks().costs.begin(), layer.marks().costs.end(), [](std::uint8_t c) { return c == 0; }));
}

TEST_CASE("update_bounds reports the cells changed since the last call, then nothing") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  CellWindow bounds;
  layer.update_bounds(bounds);
  CHECK(bounds.empty());
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));
  layer.update_bounds(bounds);
  CHECK(bounds.min_col == 40);
  CHECK(bounds.max_col == 40);
  CHECK(bounds.min_row == 50);
  CHECK(bounds.max_row == 50);
  CellWindow again;
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));  // the same mark again: no change
  layer.update_bounds(again);
  CHECK(again.empty());
  layer.add_scan(kRobot, scan(0.0, 0.0, {8.0f}));  // cleared: a change
  layer.update_bounds(again);
  CHECK(again.contains({40, 50}));
}

TEST_CASE("bad input changes nothing and crashes nothing") {
  ObstacleLayer layer(ObstacleLayerParams{}, frame(), 0.16);
  layer.add_scan(kRobot, scan(0.0, 0.0, {1.0f}));
  REQUIRE(layer.mark_count() == 1);
  CHECK_FALSE(layer.add_scan({kNaN, 2.51, 0.0}, scan(0.0, 0.0, {8.0f})));
  CHECK_FALSE(layer.add_scan({1.01, 2.51, kNaN}, scan(0.0, 0.0, {8.0f})));
  CHECK_FALSE(layer.add_scan(kRobot, scan(0.0, kNaN, {8.0f})));
  CHECK(layer.mark_count() == 1);
  // NaN and too-near ranges are skipped: they neither clear nor mark.
  CHECK(layer.add_scan(kRobot, scan(0.0, 0.0, {std::numeric_limits<float>::quiet_NaN()})));
  CHECK(layer.add_scan(kRobot, scan(0.0, 0.0, {0.05f})));
  CHECK(layer.add_scan(kRobot, scan(0.0, 0.0, {-0.5f}, -1.0)));  // negative, even with range_min below it
  CHECK(layer.mark_count() == 1);
  CHECK(layer.is_marked_at(2.01, 2.51));
  // A robot far off the frame: accepted, nothing within reach.
  CHECK(layer.add_scan({1e12, -1e12, 0.0}, scan(0.0, 0.01, std::vector<float>(360, 1.0f))));
  CHECK(layer.mark_count() == 1);
  // Just outside the frame, beams into it clear and mark as usual.
  CHECK(layer.add_scan({-0.49, 2.51, 0.0}, scan(0.0, 0.0, {1.0f})));
  CHECK(layer.is_marked_at(0.51, 2.51));
}
