// SPDX-License-Identifier: GPL-2.0-or-later
// NavMetrics on hand-moved worlds: path length, closest approach, Hall's zones and who collided with whom.
#include <catch2/catch.hpp>

#include "robot/nav_metrics.hpp"

namespace sim = rfbsim::sim;

namespace {

// A robot at the origin, one person at (x, 0), the avatar far away.
sim::World world_with_person(double person_x) {
  sim::World world;
  world.robot = sim::Robot{};
  world.avatar.pose = {50.0, 50.0, 0.0};
  sim::Person person;
  person.pose = {person_x, 0.0, 0.0};
  person.radius = 0.25;
  world.people.push_back(person);
  return world;
}

}  // namespace

TEST_CASE("metrics: path length, closest distance and zone fractions", "[metrics]") {
  sim::World world = world_with_person(3.0);
  sim::NavMetrics metrics;
  const double dt = 0.1;
  // Ten ticks far away (public zone), moving 0.1 m per tick along +y.
  for (int i = 0; i < 10; ++i) {
    world.robot->pose.y = 0.1 * i;
    metrics.observe(world, dt);
  }
  // Five ticks with the person at 1.0 m (personal), five at 0.44 m (intimate; bodies do not touch).
  world.robot->pose.y = 0.0;
  world.people[0].pose.x = 1.0;
  for (int i = 0; i < 5; ++i) metrics.observe(world, dt);
  world.people[0].pose.x = 0.44;
  for (int i = 0; i < 5; ++i) metrics.observe(world, dt);
  const sim::NavSummary s = metrics.summary();
  CHECK(s.duration == Approx(2.0));
  CHECK(s.path_length == Approx(0.9 + 0.9));  // up 0.9 m, then the jump back to y 0
  CHECK(s.min_person_distance == Approx(0.44));
  CHECK(s.intimate_fraction == Approx(0.25));
  CHECK(s.personal_fraction == Approx(0.5));
  CHECK(s.robot_on_person == 0);
  CHECK(s.person_on_robot == 0);
}

TEST_CASE("metrics: a collision is blamed on whoever closed the gap faster, once per touch", "[metrics]") {
  sim::NavMetrics metrics;
  sim::World world = world_with_person(1.0);
  // The robot drives into a standing person: robot-on-person.
  world.robot->velocity = {0.3, 0.0};
  metrics.observe(world, 0.1);
  world.people[0].pose.x = 0.42;  // gap 0.01 m
  metrics.observe(world, 0.1);
  metrics.observe(world, 0.1);  // still touching: the same collision
  // They part, then the person walks into the standing robot: person-on-robot.
  world.people[0].pose.x = 1.0;
  metrics.observe(world, 0.1);
  world.robot->velocity = {0.0, 0.0};
  world.people[0].velocity = {-1.2, 0.0};
  world.people[0].pose.x = 0.40;
  metrics.observe(world, 0.1);
  const sim::NavSummary s = metrics.summary();
  CHECK(s.robot_on_person == 1);
  CHECK(s.person_on_robot == 1);
  // The robot closed in down to 0.42 m itself; the person's walk-up to 0.40 m is not the robot's approach.
  CHECK(s.min_person_distance == Approx(0.40));
  CHECK(s.min_distance_robot_approaching == Approx(0.42));
}

TEST_CASE("metrics: the avatar counts as a person, and a world without a robot is ignored", "[metrics]") {
  sim::World world = world_with_person(10.0);
  world.avatar.pose = {0.0, 0.7, 0.0};
  sim::NavMetrics metrics;
  metrics.observe(world, 0.1);
  CHECK(metrics.summary().min_person_distance == Approx(0.7));
  CHECK(metrics.summary().personal_fraction == Approx(1.0));
  sim::World empty;
  sim::NavMetrics none;
  none.observe(empty, 0.1);
  CHECK(none.summary().duration == 0.0);
}
