// SPDX-License-Identifier: GPL-2.0-or-later
// Pedestrians walk around the participant's avatar and the robot; they never shove them. A contact is
// something the participant or the robot did, which is what the study's contact counts must mean.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "scripted_run.hpp"

namespace {

using rfbsim::sim::Party;

struct IdleRun {
  int avatar_person_contacts = 0;
  int person_robot_contacts = 0;
  double avatar_moved = 0.0;  ///< m, from where it started
  double robot_moved = 0.0;   ///< m
  double nearest_to_robot = 1e9;  ///< m, the closest any person's centre came to the robot's
};

// Steps the simulation `seconds` with no input at all and counts what the people did to the others.
IdleRun run_idle(rfbsim::sim::Simulation& simulation, int seconds) {
  const auto& world = simulation.world();
  const double ax = world.avatar.pose.x;
  const double ay = world.avatar.pose.y;
  const double rx = world.robot->pose.x;
  const double ry = world.robot->pose.y;
  IdleRun run;
  for (int tick = 0; tick < seconds * 60; ++tick) {
    simulation.step();
    for (const auto& contact : world.contacts) {
      if (contact.a == Party::Avatar && contact.b == Party::Person) ++run.avatar_person_contacts;
      if (contact.a == Party::Person && contact.b == Party::Robot) ++run.person_robot_contacts;
    }
    for (const auto& person : world.people) {
      run.nearest_to_robot = std::min(
          run.nearest_to_robot, std::hypot(person.pose.x - world.robot->pose.x, person.pose.y - world.robot->pose.y));
    }
  }
  run.avatar_moved = std::hypot(world.avatar.pose.x - ax, world.avatar.pose.y - ay);
  run.robot_moved = std::hypot(world.robot->pose.x - rx, world.robot->pose.y - ry);
  return run;
}

}  // namespace

TEST_CASE("in the lab the pedestrian passes the idle participant at the door without touching") {
  for (const int seed : {1, 2, 3, 4}) {
    auto simulation = rfbsim::test::make_scenario_simulation("lab", static_cast<std::uint64_t>(seed));
    const IdleRun run = run_idle(*simulation, 180);
    INFO("seed " << seed);
    CHECK(run.avatar_person_contacts == 0);
    CHECK(run.avatar_moved < 0.02);
    CHECK(run.robot_moved < 0.02);
  }
}

TEST_CASE("in the warehouse fifteen people walk around the idle participant and the standing robot") {
  for (const int seed : {1, 2, 3}) {
    auto simulation = rfbsim::test::make_scenario_simulation("warehouse", static_cast<std::uint64_t>(seed));
    const IdleRun run = run_idle(*simulation, 180);
    INFO("seed " << seed << ", nearest person to the robot " << run.nearest_to_robot << " m");
    CHECK(run.person_robot_contacts == 0);
    CHECK(run.avatar_person_contacts == 0);
    CHECK(run.robot_moved < 0.05);
    CHECK(run.avatar_moved < 0.05);
    CHECK(run.nearest_to_robot < 1.5);  // people did come by: the robot stands on one of their goals
  }
}

TEST_CASE("a pedestrian whose route point the robot stands on turns back beside it without pushing it") {
  // The lab's pedestrian walks corridor - doorway - back_row - doorway - corridor; the robot stands on back_row.
  rfbsim::sim::ScenarioOverrides overrides;
  overrides.robot_start = "back_row";
  auto simulation = rfbsim::test::make_scenario_simulation("lab", 3, overrides);
  REQUIRE(simulation->world().people.size() == 1);
  const IdleRun run = run_idle(*simulation, 90);
  INFO("nearest centre distance " << run.nearest_to_robot << " m");
  CHECK(run.nearest_to_robot < 1.5);  // the person did come to the robot's spot
  CHECK(run.person_robot_contacts == 0);
  CHECK(run.robot_moved < 0.02);
}
