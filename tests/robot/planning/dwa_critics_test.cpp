// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA critics one by one: obstacle clearance along every cell crossed (and driving out of inflation),
// distances at a rollout's end and nose, and ROS's oscillation flags.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "planning_test_support.hpp"
#include "robot/planning/dwa_critics.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

// A rollout through the given poses, the last one at sim_time.
Rollout rollout_of(double v, double w, std::vector<Pose2> poses) {
  Rollout rollout;
  rollout.v = v;
  rollout.w = w;
  rollout.poses = std::move(poses);
  rollout.end = rollout.poses.size() - 1;
  return rollout;
}

}  // namespace

TEST_CASE("the obstacle critic scores the highest cost along a rollout and rejects obstacles") {
  const CostmapGrid grid = costmap_from_text({"......", ".4..#.", ".2....", "..i...", "......"}, 0.1);
  DwaScene scene;
  scene.grid = &grid;
  scene.pose = {0.05, 0.05, 0.0};
  ObstacleCritic critic;
  REQUIRE(critic.prepare(scene));
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.05, 0.05, 0}, {0.15, 0.05, 0}, {0.15, 0.25, 0}})) == 50.0);
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.05, 0.05, 0}, {0.15, 0.35, 0}})) == 100.0);
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.05, 0.05, 0}, {0.25, 0.15, 0}})) < 0.0);   // inscribed
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.05, 0.05, 0}, {0.45, 0.35, 0}})) < 0.0);   // lethal
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.05, 0.05, 0}, {-0.05, 0.05, 0}})) < 0.0);  // off the grid
}

TEST_CASE("the obstacle critic checks every cell between rollout points, not only the points") {
  // Both points lie in free cells, but the chord between them clips the inscribed cell's corner.
  const CostmapGrid grid = costmap_from_text({"...", ".i.", "..."}, 0.1);
  DwaScene scene;
  scene.grid = &grid;
  scene.pose = {0.09, 0.15, 0.0};
  ObstacleCritic critic;
  REQUIRE(critic.prepare(scene));
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.09, 0.15, 0}, {0.15, 0.09, 0}})) < 0.0);
  CHECK(critic.score(rollout_of(0.1, 0.0, {{0.09, 0.15, 0}, {0.05, 0.05, 0}, {0.15, 0.05, 0}})) == 0.0);
}

TEST_CASE("a robot in an inscribed cell may drive out, but not stay in") {
  const CostmapGrid grid = costmap_from_text({"......", ".iii..", ".iii.#", ".iii..", "......"}, 0.1);
  DwaScene scene;
  scene.grid = &grid;
  scene.pose = {0.25, 0.25, 0.0};
  ObstacleCritic critic;
  REQUIRE(critic.prepare(scene));
  // Out to the right through inscribed cells: legal; what it crossed while leaving is not scored.
  CHECK(critic.score(rollout_of(0.2, 0.0, {{0.25, 0.25, 0}, {0.35, 0.25, 0}, {0.45, 0.25, 0}})) == 0.0);
  // Out, then back into inflation: illegal.
  CHECK(critic.score(rollout_of(0.2, 0.0, {{0.25, 0.25, 0}, {0.45, 0.25, 0}, {0.35, 0.25, 0}})) < 0.0);
  // Still inscribed at sim_time (turning in place): illegal.
  CHECK(critic.score(rollout_of(0.0, 1.0, {{0.25, 0.25, 0}, {0.25, 0.25, 0.5}})) < 0.0);
  // A robot inside a lethal cell: nothing is legal.
  scene.pose = {0.55, 0.25, 0.0};
  REQUIRE(critic.prepare(scene));
  CHECK(critic.score(rollout_of(0.2, 0.0, {{0.55, 0.25, 0}, {0.55, 0.45, 0}})) < 0.0);
}

TEST_CASE("a map critic reads the distance at the end, or at the nose ahead of it") {
  const CostmapGrid grid = costmap_from_text({"......", "......", "....##"}, 0.1);
  DistanceGrid map;
  map.compute(grid, {static_cast<std::int32_t>(grid.index({0, 0}))});
  DwaScene scene;
  scene.grid = &grid;
  scene.path_map = &map;
  scene.pose = {0.05, 0.25, 0.0};
  scene.local_goal = {0.55, 0.25};
  MapDistanceCritic end("path_distance", MapDistanceCritic::Target::Path, 0.0, false);
  MapDistanceCritic nose("alignment", MapDistanceCritic::Target::Path, 0.2, true);
  REQUIRE(end.prepare(scene));
  REQUIRE(nose.prepare(scene));
  const Rollout to_right = rollout_of(0.1, 0.0, {{0.05, 0.25, 0}, {0.25, 0.05, 0.0}});
  CHECK(end.score(to_right) == Approx(0.2));
  CHECK(nose.score(to_right) == Approx(0.2 + 0.2));  // the nose (0.45, 0.05) is over the wall
  const Rollout facing_down = rollout_of(0.1, 0.0, {{0.05, 0.25, 0}, {0.25, 0.25, -std::numbers::pi / 2}});
  CHECK(nose.score(facing_down) == Approx(0.2));  // nose at (0.25, 0.05)
  // The end in a wall, or off the grid, is illegal.
  CHECK(end.score(rollout_of(0.1, 0.0, {{0.05, 0.25, 0}, {0.45, 0.05, 0}})) < 0.0);
  CHECK(end.score(rollout_of(0.1, 0.0, {{0.05, 0.25, 0}, {0.65, 0.05, 0}})) < 0.0);
  // Within one nose length of the local goal the alignment critic switches off.
  scene.pose = {0.45, 0.25, 0.0};
  CHECK_FALSE(nose.prepare(scene));
  CHECK(end.prepare(scene));
}

TEST_CASE("oscillation: a reversed turn in place locks out the first direction until the robot moves") {
  OscillationCritic critic(0.05, 0.2, 0.1);
  const Rollout left = rollout_of(0.0, 0.5, {{}});
  const Rollout right = rollout_of(0.0, -0.5, {{}});
  const Rollout left_arc = rollout_of(0.3, 0.5, {{}});
  CHECK(critic.score(left) == 0.0);
  CHECK(critic.score(right) == 0.0);
  critic.update({0.0, 0.0, 0.0}, 0.0, 0.5);  // turn left in place: nothing locked yet
  CHECK(critic.score(right) == 0.0);
  critic.update({0.0, 0.0, 0.05}, 0.0, -0.5);  // then right: left is locked out, driving arcs included
  CHECK(critic.score(left) < 0.0);
  CHECK(critic.score(left_arc) < 0.0);
  CHECK(critic.score(right) == 0.0);
  critic.update({0.03, 0.0, 0.05}, 0.1, 0.0);  // moved 3 cm from where it was locked: still locked
  CHECK(critic.score(left) < 0.0);
  critic.update({0.06, 0.0, 0.05}, 0.1, 0.0);  // 6 cm: free again
  CHECK(critic.score(left) == 0.0);
  CHECK(critic.score(right) == 0.0);

  SECTION("turning far enough frees it too") {
    critic.update({0.0, 0.0, 0.0}, 0.0, -0.5);
    critic.update({0.0, 0.0, 0.0}, 0.0, 0.5);
    CHECK(critic.score(right) < 0.0);
    critic.update({0.0, 0.0, 0.25}, 0.0, 0.5);
    CHECK(critic.score(right) == 0.0);
  }
  SECTION("turns while driving set no flags; reversing the drive does") {
    critic.update({0.0, 0.0, 0.0}, 0.2, 0.5);
    critic.update({0.0, 0.0, 0.0}, 0.2, -0.5);
    CHECK(critic.score(left) == 0.0);
    critic.update({0.0, 0.0, 0.0}, -0.1, 0.0);
    CHECK(critic.score(rollout_of(0.2, 0.0, {{}})) < 0.0);
    CHECK(critic.score(rollout_of(-0.1, 0.0, {{}})) == 0.0);
    critic.reset();
    CHECK(critic.score(rollout_of(0.2, 0.0, {{}})) == 0.0);
  }
}
