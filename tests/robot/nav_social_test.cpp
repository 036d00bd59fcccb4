// SPDX-License-Identifier: GPL-2.0-or-later
// Social behaviour on hand-made maps: the proxemic layer keeps the robot farther from a person standing in
// a corridor, and a person blocking a corridor makes the robot replan the long way round.
#include <catch2/catch.hpp>

#include "nav_run.hpp"
#include "scenario/robot_params_yaml.hpp"

namespace sim = rfbsim::sim;
using rfbsim::test::BareWorld;

namespace {

/// Drives the length of a 3.6 m wide corridor past a person standing 0.4 m off its middle; returns the run.
rfbsim::test::NavRun pass_standing_person(bool proxemic, std::uint64_t seed) {
  const sim::GridMap corridor = rfbsim::test::walled_room(14.0, 3.6);
  sim::World world = rfbsim::test::bare_world(corridor, {1.0, 1.8, 0.0}, {13.5, 0.4, 0.0});
  world.people.push_back(rfbsim::test::standing_person(7.0, 2.2));
  auto setup = rfbsim::test::goto_setup({12.8, 1.8, 0.0}, seed);
  setup.params.global_costmap.use_proxemic_layer = proxemic;
  setup.params.local_costmap.use_proxemic_layer = proxemic;
  BareWorld bare(std::move(world), setup);
  return bare.run_to_goal(120.0);
}

}  // namespace

TEST_CASE("nav: passing a standing person in a corridor, the proxemic layer keeps more distance", "[nav][social]") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto with = pass_standing_person(true, seed);
    const auto without = pass_standing_person(false, seed);
    INFO("seed " << seed << ": closest with proxemic " << with.metrics.min_person_distance << " m, without "
                 << without.metrics.min_person_distance << " m");
    REQUIRE(with.arrived);
    REQUIRE(without.arrived);
    CHECK(with.metrics.min_person_distance > without.metrics.min_person_distance + 0.1);
    // Neither touches the person; with the layer the robot stays out of the intimate zone.
    CHECK(without.metrics.robot_on_person == 0);
    CHECK(with.metrics.robot_on_person == 0);
    CHECK(with.metrics.min_person_distance > 0.45);
  }
}

TEST_CASE("nav: people blocking the short corridor make the robot replan the long way round", "[nav][social]") {
  // Two corridors between the west and east halls: a short one straight across (1.4 m wide) and a long
  // one around the south. Two people wait in the north-east corner, out of everyone's way, and step side by
  // side into the middle of the short corridor (leaving 0.15 m at either wall) once the robot has planned
  // through it.
  sim::GridMap map = rfbsim::test::walled_room(16.0, 10.0);
  rfbsim::test::add_wall(map, 5.0, 6.7, 11.0, 10.0);  // north of the short corridor
  rfbsim::test::add_wall(map, 5.0, 2.5, 11.0, 5.3);   // between the two corridors
  sim::World world = rfbsim::test::bare_world(map, {2.0, 6.0, 0.0}, {15.3, 0.7, 0.0});
  world.people.push_back(rfbsim::test::standing_person(13.5, 9.2, 1));
  world.people.push_back(rfbsim::test::standing_person(14.5, 9.2, 2));
  BareWorld bare(std::move(world), rfbsim::test::goto_setup({14.0, 6.0, 0.0}));
  std::vector<sim::RobotEvent> early;
  for (int i = 0; i < 3 * 60; ++i) {
    bare.step();
    early.insert(early.end(), bare.world().robot_events.begin(), bare.world().robot_events.end());
  }
  // The first plan runs through the short corridor: about 12 m.
  REQUIRE(early.size() >= 2);
  CHECK(early[1].state == sim::RobotState::Moving);
  CHECK_THAT(early[1].detail, Catch::Contains("following a 12.") || Catch::Contains("following a 11."));
  bare.world_mut().people[0].pose = {8.0, 5.7, 0.0};
  bare.world_mut().people[1].pose = {8.0, 6.3, 0.0};
  const auto run = bare.run_to_goal(240.0);
  INFO(run.last_detail);
  REQUIRE(run.arrived);
  CHECK(run.metrics.robot_on_person == 0);
  // The robot went the long way round the south corridor: over 15 m driven, where the short way is 12 m.
  CHECK(run.metrics.path_length > 15.0);
  CHECK_FALSE(run.hit_wall);
}

TEST_CASE("nav: the goal is a person only when someone stands within the social distance of it", "[nav][social]") {
  sim::NavigatorParams params;  // person_goal_distance 1.2 m, standing below 0.1 m/s
  const sim::Pose2 goal{5.0, 5.0, 0.0};
  const sim::SeenPerson far{{6.3, 5.0}, {0.0, 0.0}, 0.25};      // 1.3 m off: not at the goal
  const sim::SeenPerson near{{5.0, 6.0}, {0.05, 0.0}, 0.25};    // 1.0 m off, shuffling: at the goal
  const sim::SeenPerson nearer{{5.5, 5.0}, {0.0, 0.0}, 0.25};   // 0.5 m off, standing: nearer still
  const sim::SeenPerson walker{{5.0, 5.1}, {1.2, 0.0}, 0.25};   // crossing the goal: not a goal
  CHECK_FALSE(sim::goal_person_at(goal, std::vector<sim::SeenPerson>{far, walker}, params));
  CHECK(sim::goal_person_at(goal, std::vector<sim::SeenPerson>{far, near}, params) == near.position);
  CHECK(sim::goal_person_at(goal, std::vector<sim::SeenPerson>{near, walker, nearer}, params) == nearer.position);
  params.person_goal_distance = 2.0;
  CHECK(sim::goal_person_at(goal, std::vector<sim::SeenPerson>{far}, params) == far.position);
}

TEST_CASE("nav: the social settings are scenario keys, checked with the key named", "[nav][social]") {
  const auto parse = [](const std::string& text) {
    sim::RobotParams params;
    sim::parse_robot_params(sim::YamlField(YAML::Load(text), "social.yaml"), params);
    return params;
  };
  const sim::RobotParams params = parse(
      "dwa: {people_personal_clearance: 0.6, people_walking_speed: 0.3}\n"
      "move_base: {person_goal_distance: 2.0, person_goal_standing_speed: 0.2}\n"
      "proxemic: {amplitude: 100, covariance: 0.1}\n");
  CHECK(params.dwa.people_personal_clearance == 0.6);
  CHECK(params.dwa.people_walking_speed == 0.3);
  CHECK(params.navigator.person_goal_distance == 2.0);
  CHECK(params.navigator.person_goal_standing_speed == 0.2);
  CHECK(params.local_costmap.proxemic.covariance == 0.1);  // one proxemic model for both costmaps
  CHECK_THROWS_WITH(parse("dwa: {people_personal_clearance: -0.1}"), Catch::Contains("dwa.people_personal_clearance"));
  CHECK_THROWS_WITH(parse("dwa: {people_walking_speed: fast}"), Catch::Contains("people_walking_speed"));
  // Closer than Hall's intimate zone is no social distance.
  CHECK_THROWS_WITH(parse("move_base: {person_goal_distance: 0.3}"), Catch::Contains("person_goal_distance"));
  CHECK_THROWS_WITH(parse("proxemic: {covariance: 0}"), Catch::Contains("proxemic.covariance"));
}
