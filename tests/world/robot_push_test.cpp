// SPDX-License-Identifier: GPL-2.0-or-later
// A participant who walks into the robot pushes it (SEAN-EP: 18 % of participants did), and the push is
// measurable: the robot moves and an avatar-robot contact event carries the tick and the impulse.
#include <catch2/catch.hpp>

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
