// SPDX-License-Identifier: GPL-2.0-or-later
// The robot's navigation on small hand-made maps: reaching a goal, its events, refusing impossible goals,
// giving up with a reason when no route exists, and determinism.
#include <catch2/catch.hpp>

#include <cstring>

#include "nav_run.hpp"

namespace sim = rfbsim::sim;
using rfbsim::test::BareWorld;

namespace {

const sim::Pose2 kParked{9.5, 0.5, 0.0};  // the avatar, out of the way in a corner

bool has_state(const std::vector<sim::RobotEvent>& events, sim::RobotState state) {
  for (const auto& event : events) {
    if (event.state == state) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("nav: in an empty room the robot reaches its goal, localizing with AMCL", "[nav]") {
  const sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  const sim::Pose2 goal{8.5, 6.5, 0.0};
  BareWorld bare(rfbsim::test::bare_world(room, {1.5, 1.5, 0.0}, kParked), rfbsim::test::goto_setup(goal));
  const auto run = bare.run_to_goal(90.0);
  INFO(run.last_detail);
  REQUIRE(run.arrived);
  const sim::Robot& robot = *bare.world().robot;
  CHECK(std::hypot(robot.pose.x - goal.x, robot.pose.y - goal.y) <= 0.35 + 0.05);
  CHECK_FALSE(run.hit_wall);
  CHECK(run.max_estimate_error < 0.2);
  // About the straight distance (8.6 m) at about 0.3 m/s: neither a detour nor a crawl.
  CHECK(run.metrics.path_length < 8.6 * 1.25);
  CHECK(run.end_time < 8.6 / 0.3 * 1.6);
  // The events in order: planning, moving, arrived.
  REQUIRE(run.events.size() >= 3);
  CHECK(run.events[0].state == sim::RobotState::Planning);
  CHECK(run.events[1].state == sim::RobotState::Moving);
  CHECK(run.events.back().state == sim::RobotState::Arrived);
  CHECK(robot.state == sim::RobotState::Arrived);
  // Arrived means stopped.
  for (int i = 0; i < 60; ++i) bare.step();
  CHECK(bare.world().robot->velocity.norm() < 0.01);
}

TEST_CASE("nav: with ground_truth localization the planners use the true pose", "[nav]") {
  const sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  auto setup = rfbsim::test::goto_setup({8.0, 2.0, 0.0});
  setup.params.localization = sim::Localization::GroundTruth;
  BareWorld bare(rfbsim::test::bare_world(room, {1.5, 6.0, 0.0}, kParked), setup);
  const auto run = bare.run_to_goal(90.0);
  REQUIRE(run.arrived);
  // The estimate is taken each control cycle; the truth moves on between cycles by at most 0.1 s of motion.
  CHECK(run.max_estimate_error < 0.06);
}

TEST_CASE("nav: goals inside a wall or off the map are refused with a clear reason", "[nav]") {
  sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  rfbsim::test::add_wall(room, 4.0, 0.0, 4.5, 5.0);
  BareWorld bare(rfbsim::test::bare_world(room, {1.5, 1.5, 0.0}, kParked), sim::RobotSetup{});
  bare.step();
  auto& world = bare.world_mut();
  const auto in_wall = bare.stack().send_goal(world, {4.2, 2.0, 0.0});
  REQUIRE(in_wall);
  CHECK_THAT(*in_wall, Catch::Contains("inside a wall or prop") && Catch::Contains("(4.20, 2.00)"));
  CHECK(world.robot->state == sim::RobotState::Failed);
  // Touching a wall is as bad as inside it: the footprint would overlap.
  const auto touching = bare.stack().send_goal(world, {4.6, 2.0, 0.0});
  REQUIRE(touching);
  const auto off_map = bare.stack().send_goal(world, {25.0, -3.0, 0.0});
  REQUIRE(off_map);
  CHECK_THAT(*off_map, Catch::Contains("off the map"));
  const auto not_a_number = bare.stack().send_goal(world, {std::nan(""), 1.0, 0.0});
  REQUIRE(not_a_number);
  CHECK_THAT(*not_a_number, Catch::Contains("not a number"));
  // Each refusal is reported as an event too, with its reason, and the robot does not move.
  bare.step();
  int failed_events = 0;
  for (const auto& event : world.robot_events) {
    if (event.state == sim::RobotState::Failed && event.detail.find("goal refused") != std::string::npos) ++failed_events;
  }
  CHECK(failed_events == 4);
  CHECK(world.robot->velocity.norm() < 1e-9);
  const auto fine = bare.stack().send_goal(world, {2.5, 2.5, 0.0});
  CHECK_FALSE(fine);
  CHECK(world.robot->state == sim::RobotState::Planning);
}

TEST_CASE("nav: with no route to the goal the robot recovers, then gives up with the reason", "[nav]") {
  // A closed box around the goal: the planner never finds a way in.
  sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  rfbsim::test::add_wall(room, 6.0, 3.0, 9.0, 3.2);
  rfbsim::test::add_wall(room, 6.0, 6.0, 9.0, 6.2);
  rfbsim::test::add_wall(room, 6.0, 3.0, 6.2, 6.2);
  rfbsim::test::add_wall(room, 8.8, 3.0, 9.0, 6.2);
  BareWorld bare(rfbsim::test::bare_world(room, {1.5, 1.5, 0.0}, kParked), rfbsim::test::goto_setup({7.5, 4.6, 0.0}));
  const auto run = bare.run_to_goal(180.0);
  REQUIRE(run.failed);
  CHECK_FALSE(run.arrived);
  CHECK(has_state(run.events, sim::RobotState::Recovering));
  CHECK_THAT(run.last_detail, Catch::Contains("gave up") && Catch::Contains("no global plan"));
  CHECK(bare.world().robot->state == sim::RobotState::Failed);
}

TEST_CASE("nav: the same seed drives the same path bit for bit, another seed another", "[nav]") {
  const sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  // The robot's true pose and estimate at every tick of 15 s.
  const auto trace = [&](std::uint64_t seed) {
    BareWorld bare(rfbsim::test::bare_world(room, {1.5, 1.5, 0.3}, kParked),
                   rfbsim::test::goto_setup({8.0, 6.0, 0.0}, seed));
    std::vector<double> poses;
    for (int i = 0; i < 15 * 60; ++i) {
      bare.step();
      const auto& r = *bare.world().robot;
      poses.insert(poses.end(), {r.pose.x, r.pose.y, r.pose.yaw, r.estimate.x, r.estimate.y, r.estimate.yaw});
    }
    return poses;
  };
  const auto a = trace(5);
  const auto b = trace(5);
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  CHECK(a != trace(6));
}

TEST_CASE("nav: a goal with a heading is reached facing it", "[nav]") {
  const sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  auto setup = rfbsim::test::goto_setup({7.0, 4.0, 1.5708});
  setup.params.navigator.yaw_goal_tolerance = 0.2;
  BareWorld bare(rfbsim::test::bare_world(room, {2.0, 4.0, 0.0}, kParked), setup);
  const auto run = bare.run_to_goal(90.0);
  REQUIRE(run.arrived);
  CHECK(std::abs(std::remainder(bare.world().robot->pose.yaw - 1.5708, 2.0 * M_PI)) < 0.2 + 0.05);
}

TEST_CASE("nav: a patrol goes round its waypoints, pausing at each", "[nav]") {
  const sim::GridMap room = rfbsim::test::walled_room(10.0, 8.0);
  sim::RobotSetup setup;
  setup.mission.kind = sim::MissionSpec::Kind::Patrol;
  setup.mission.waypoints = {{2.0, 2.0, 0.0}, {7.0, 2.0, 0.0}, {7.0, 6.0, 0.0}};
  setup.mission.waypoint_names = {"a", "b", "c"};
  setup.params.navigator.waypoint_pause = 2.0;
  BareWorld bare(rfbsim::test::bare_world(room, {2.0, 2.0, 0.0}, kParked), setup);
  std::vector<double> arrivals;      // s
  std::vector<double> next_plans;    // s: planning after an arrival
  while (bare.world().time < 150.0 && arrivals.size() < 4) {
    bare.step();
    for (const auto& event : bare.world().robot_events) {
      if (event.state == sim::RobotState::Arrived) arrivals.push_back(bare.world().time);
      if (event.state == sim::RobotState::Planning && !arrivals.empty()) next_plans.push_back(bare.world().time);
      CHECK(event.state != sim::RobotState::Failed);
    }
  }
  // a (where it starts), b, c, and a again.
  REQUIRE(arrivals.size() == 4);
  REQUIRE(next_plans.size() >= 3);
  for (std::size_t i = 0; i < 3; ++i) CHECK(next_plans[i] - arrivals[i] == Approx(2.0).margin(0.15));
  const auto& r = *bare.world().robot;
  CHECK(std::hypot(r.pose.x - 2.0, r.pose.y - 2.0) < 0.35 + 0.05);
}
