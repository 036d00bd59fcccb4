// SPDX-License-Identifier: GPL-2.0-or-later
// Long runs of the shipped scenarios through every system: nobody leaves the map or walks into a wall,
// no number goes NaN, and a participant who walks into the robot pushes it (SEAN-EP: 18 % did).
#include <catch2/catch.hpp>

#include <cmath>

#include "crowd/route_planner.hpp"
#include "scripted_run.hpp"

using rfbsim::test::ScriptedKey;

namespace {

bool finite(const std::vector<double>& values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("ten minutes of warehouse: nobody leaves the map or stands in a wall, no NaN", "[busy]") {
  auto simulation = rfbsim::test::make_scenario_simulation("warehouse", 5, {}, true);
  const auto& world = simulation->world();
  // The participant wanders: walk, turn a little, walk, for the whole ten minutes.
  constexpr std::uint64_t kTicks = 10 * 60 * 60;
  std::uint64_t worst_tick = 0;
  int bad = 0;
  simulation->apply_key('w', true);
  for (std::uint64_t tick = 0; tick < kTicks; ++tick) {
    if (tick % 240 == 0) simulation->apply_key('a', true);
    if (tick % 240 == 40) simulation->apply_key('a', false);
    simulation->step();
    const auto poses = rfbsim::test::agent_poses(world);
    bool ok = finite(poses);
    // Centres stay on the map and out of walls and props (bodies may touch them, not enter).
    for (std::size_t i = 0; ok && i + 2 < poses.size(); i += 3) {
      ok = world.map.contains(poses[i], poses[i + 1]) && !world.obstacles.is_occupied_at(poses[i], poses[i + 1]);
    }
    if (!ok && bad++ == 0) worst_tick = tick;
  }
  INFO("first bad tick " << worst_tick);
  CHECK(bad == 0);
  CHECK(world.people.size() == 15);
}

namespace sim = rfbsim::sim;

TEST_CASE("every pair of the warehouse's crowd goals is joined by a route that keeps the full clearance") {
  sim::Scenario scenario = sim::load_scenario(std::string(RFBSIM_SCENARIO_DIR) + "/warehouse.yaml");
  const sim::World world = sim::make_world(scenario);
  const sim::RoutePlanner planner(world.obstacles);
  const auto& goals = scenario.crowd.goals;
  REQUIRE(goals.size() >= 10);
  for (const Eigen::Vector2d& from : goals) {
    for (const Eigen::Vector2d& to : goals) {
      if (from == to) continue;
      INFO("from " << from.transpose() << " to " << to.transpose());
      const sim::PlannedRoute route = planner.plan(from, to, 0.3);
      REQUIRE(!route.waypoints.empty());
      CHECK(route.clearance == 0.3);
      CHECK(route.waypoints.back() == to);
      CHECK(route.waypoints.size() <= 6);  // straightened: a few legs, not a staircase of cells
      Eigen::Vector2d at = from;
      for (const Eigen::Vector2d& w : route.waypoints) {
        CHECK(planner.line_clear(at, w, route.clearance));
        at = w;
      }
    }
  }
}
