// SPDX-License-Identifier: GPL-2.0-or-later
// A participant who walks into the robot pushes it (SEAN-EP: 18 % of participants did), and the push is
// measurable: the robot moves and an avatar-robot contact event carries the tick and the impulse.
// Pedestrians do not: one whose route leads to where the robot stands turns back beside it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "scripted_run.hpp"

TEST_CASE("walking into the standing robot pushes it, and the contact is an event") {
  // In the warehouse's cross aisle: the avatar 1.5 m west of the robot, facing it, nobody else around.
  rfbsim::sim::ScenarioOverrides overrides;
  overrides.robot_start = "10.0,18.5,0";
  overrides.avatar_start = "8.5,18.5,0";
  overrides.crowd_count = 0;
  auto simulation = rfbsim::test::make_scenario_simulation("warehouse", 1, overrides);
  const auto& world = simulation->world();
  REQUIRE(world.robot);
  const double robot_x0 = world.robot->pose.x;
  int avatar_robot_contacts = 0;
  double impulse = 0.0;
  simulation->apply_key('w', true);
  for (int tick = 0; tick < 5 * 60; ++tick) {
    simulation->step();
    for (const auto& contact : world.contacts) {
      if (contact.a == rfbsim::sim::Party::Avatar && contact.b == rfbsim::sim::Party::Robot) {
        ++avatar_robot_contacts;
        impulse += contact.impulse;
        CHECK(contact.tick == world.tick - 1);
      }
    }
  }
  CHECK(avatar_robot_contacts >= 1);
  CHECK(impulse > 0.0);
  CHECK(world.robot->pose.x - robot_x0 > 0.3);
  // The avatar stays behind the robot: it pushes, it does not pass through.
  CHECK(world.avatar.pose.x < world.robot->pose.x);
}

TEST_CASE("a pedestrian whose route point the robot stands on turns back beside it without pushing it") {
  // The lab's pedestrian walks corridor - doorway - back_row - doorway - corridor; the robot stands on back_row.
  rfbsim::sim::ScenarioOverrides overrides;
  overrides.robot_start = "back_row";
  auto simulation = rfbsim::test::make_scenario_simulation("lab", 3, overrides);
  const auto& world = simulation->world();
  REQUIRE(world.robot);
  REQUIRE(world.people.size() == 1);
  const double robot_x0 = world.robot->pose.x;
  const double robot_y0 = world.robot->pose.y;
  double nearest = 1e9;
  int person_robot_contacts = 0;
  for (int tick = 0; tick < 90 * 60; ++tick) {
    simulation->step();
    const auto& person = world.people[0];
    nearest = std::min(nearest, std::hypot(person.pose.x - world.robot->pose.x, person.pose.y - world.robot->pose.y));
    for (const auto& contact : world.contacts) {
      if (contact.a == rfbsim::sim::Party::Person && contact.b == rfbsim::sim::Party::Robot) ++person_robot_contacts;
    }
  }
  INFO("nearest centre distance " << nearest << " m");
  CHECK(nearest < 1.5);  // the person did come to the robot's spot
  CHECK(person_robot_contacts == 0);
  CHECK(std::hypot(world.robot->pose.x - robot_x0, world.robot->pose.y - robot_y0) < 0.02);
}
