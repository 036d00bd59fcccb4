// SPDX-License-Identifier: GPL-2.0-or-later
// The robot in the shipped lab: across the room among desks while the pedestrian walks, and the SEAN-EP
// mission (to the participant's start, where the participant still stands).
#include <catch2/catch.hpp>

#include "nav_run.hpp"

namespace sim = rfbsim::sim;

TEST_CASE("nav: in the lab the robot crosses the room to the front row", "[nav][scene]") {
  for (std::uint64_t seed : {1u, 2u}) {
    sim::ScenarioOverrides overrides;
    overrides.robot_goal = "front_row";
    auto simulation = rfbsim::test::make_mission_simulation("lab", seed, overrides);
    const auto run = rfbsim::test::run_to_goal(*simulation, 120.0);
    INFO("seed " << seed << ": " << run.last_detail);
    REQUIRE(run.arrived);
    CHECK_FALSE(run.hit_wall);
    CHECK(run.metrics.robot_on_person == 0);
    CHECK(run.max_estimate_error < 0.25);
  }
}

TEST_CASE("nav: sent to the participant's start while they stand there, the robot stops at social distance",
          "[nav][scene]") {
  // The default person_goal_distance (1.2 m, Hall's personal/social boundary), then a replication's 2 m.
  for (const double stop : {1.2, 2.0}) {
    sim::Scenario scenario = sim::load_scenario(std::string(RFBSIM_SCENARIO_DIR) + "/lab.yaml");
    sim::RobotParams params = scenario.robot.params;
    params.navigator.person_goal_distance = stop;
    auto simulation = rfbsim::test::make_mission_simulation("lab", 1, {}, &params);
    const auto& world = simulation->world();
    const auto run = rfbsim::test::run_to_goal(*simulation, 120.0);
    INFO("stop at " << stop << " m: " << run.last_detail);
    REQUIRE(run.arrived);
    CHECK(run.last_detail.find("from the person at the goal") != std::string::npos);
    // Arrived on the cycle it came within the distance, then braked: at most one period and a stop short.
    const double centres =
        std::hypot(world.robot->pose.x - world.avatar.pose.x, world.robot->pose.y - world.avatar.pose.y);
    CHECK(centres <= stop + 1e-6);
    CHECK(centres > stop - 0.12);
    CHECK(run.metrics.robot_on_person == 0);
  }
}

TEST_CASE("nav: status.json reports the robot's state and estimate", "[nav][scene]") {
  auto simulation = rfbsim::test::make_mission_simulation("lab", 1);
  for (int i = 0; i < 60; ++i) simulation->step();
  const std::string json = sim::status_json(simulation->world(), 0, 0);
  CHECK_THAT(json, Catch::Contains("\"state\":\"moving\"") && Catch::Contains("\"estimate\":{"));
}
