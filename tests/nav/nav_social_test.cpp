// SPDX-License-Identifier: GPL-2.0-or-later
// Social behaviour on hand-made maps: the proxemic layer keeps the robot farther from a person standing in
// a corridor, and a person blocking a corridor makes the robot replan the long way round.
#include <catch2/catch.hpp>

#include "nav_run.hpp"

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
