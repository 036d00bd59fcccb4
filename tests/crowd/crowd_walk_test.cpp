// SPDX-License-Identifier: GPL-2.0-or-later
// People walking tiny maps: passing head-on, a two-way corridor, a lone walker's speed, around a shelf,
// past the participant's avatar. Motion without physics (move_people_freely).
#include <catch2/catch.hpp>

#include <deque>

#include "crowd_test_support.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

// One person per goal, each standing at the goal's route after the crowd is built; returns the crowd.
// A one-point route means "walk there and stand", so the test chooses where everyone starts.
Crowd walkers_to(World& world, const std::vector<Eigen::Vector2d>& starts, const std::vector<Eigen::Vector2d>& goals,
                 SocialForceParams params = {}) {
  CrowdSpec spec;
  spec.count = static_cast<int>(goals.size());
  for (const Eigen::Vector2d& g : goals) spec.routes.push_back({g});
  Crowd crowd(world, spec, params);
  world.people = crowd.spawn();
  for (std::size_t i = 0; i < starts.size(); ++i) {
    world.people[i].pose = {starts[i].x(), starts[i].y(), std::atan2(goals[i].y() - starts[i].y(),
                                                                     goals[i].x() - starts[i].x())};
  }
  return crowd;
}

double distance(const Person& a, const Person& b) { return std::hypot(a.pose.x - b.pose.x, a.pose.y - b.pose.y); }

}  // namespace

TEST_CASE("two people walking head-on pass without touching and both arrive") {
  World world = walled_world(20.0, 10.0, 0.25);
  const Eigen::Vector2d a(3, 5);
  const Eigen::Vector2d b(17, 5);
  Crowd crowd = walkers_to(world, {a, b}, {b, a});
  double closest = 1e9;
  for (int t = 0; t < 60 * 25; ++t) {
    tick(crowd, world, 1.0 / 60.0);
    check_people_clear_of_walls(world);
    closest = std::min(closest, distance(world.people[0], world.people[1]));
  }
  CHECK(closest > world.people[0].radius + world.people[1].radius);
  CHECK((Eigen::Vector2d(world.people[0].pose.x, world.people[0].pose.y) - b).norm() < 0.3);
  CHECK((Eigen::Vector2d(world.people[1].pose.x, world.people[1].pose.y) - a).norm() < 0.3);
  WARN("head-on: closest centre distance " << closest << " m");
}

TEST_CASE("Helbing-Molnar 1995 has an exact head-on pair meet face to face (why Moussaid is the default)") {
  World world = walled_world(20.0, 10.0, 0.25);
  SocialForceParams params;
  params.model = PedestrianModel::HelbingMolnar1995;
  Crowd crowd = walkers_to(world, {{3, 5}, {17, 5}}, {{17, 5}, {3, 5}}, params);
  double closest = 1e9;
  double sideways = 0.0;
  for (int t = 0; t < 60 * 25; ++t) {
    tick(crowd, world, 1.0 / 60.0);
    closest = std::min(closest, distance(world.people[0], world.people[1]));
    for (const Person& p : world.people) sideways = std::max(sideways, std::abs(p.pose.y - 5.0));
  }
  // Forces along the line between them only: nobody steps aside, so they meet chest to chest (they do not
  // walk into each other: one backs off as the other presses on).
  CHECK(sideways < 0.01);
  CHECK(closest < world.people[0].radius + world.people[1].radius + 0.1);
}

TEST_CASE("a 2.5 m corridor with ten people going both ways keeps flowing for two minutes") {
  // 22 m x 3 m at 0.25 m: border walls leave 2.5 m between them, 20.5 m of corridor.
  World world = walled_world(22.0, 3.0, 0.25);
  CrowdSpec spec;
  spec.count = 10;
  spec.routes = {{{1.5, 1.5}, {20.5, 1.5}}};
  Crowd crowd(world, spec);
  world.people = crowd.spawn();
  const double dt = 0.05;
  const int window = static_cast<int>(10.0 / dt);
  // Each person's positions over the last 10 s.
  std::vector<std::deque<Eigen::Vector2d>> history(world.people.size());
  int both_ways = 0;
  for (const Person& p : world.people) both_ways += std::cos(p.pose.yaw) > 0 ? 1 : -1;
  CHECK(std::abs(both_ways) < 10);  // not everyone the same way
  for (int t = 0; t < static_cast<int>(120.0 / dt); ++t) {
    tick(crowd, world, dt);
    check_people_clear_of_walls(world);
    for (std::size_t i = 0; i < world.people.size(); ++i) {
      history[i].emplace_back(world.people[i].pose.x, world.people[i].pose.y);
      if (static_cast<int>(history[i].size()) > window) history[i].pop_front();
      if (static_cast<int>(history[i].size()) == window) {
        // Stuck = every point of the window within 0.1 m of its first.
        double farthest = 0.0;
        for (const Eigen::Vector2d& q : history[i]) farthest = std::max(farthest, (q - history[i].front()).norm());
        INFO("person " << i + 1 << " at t = " << t * dt << " s");
        REQUIRE(farthest >= 0.1);
      }
    }
  }
  int ends_reached = 0;
  for (std::size_t i = 0; i < world.people.size(); ++i) ends_reached += crowd.goals_reached(i);
  CHECK(ends_reached >= 10 * 3);  // 19 m at about 1.3 m/s: some 8 ends each in 120 s when nobody is in the way
  WARN("corridor: route ends reached in 120 s by 10 people: " << ends_reached);
}

TEST_CASE("a lone person on a long free route walks at its desired speed") {
  World world = walled_world(50.0, 6.0, 0.25);
  Crowd crowd = walkers_to(world, {{2, 3}}, {{48, 3}});
  const double desired = world.people[0].desired_speed;
  const double dt = 1.0 / 60.0;
  double entered = -1.0;
  double left = -1.0;
  for (int t = 0; t < 60 * 60 && left < 0.0; ++t) {
    tick(crowd, world, dt);
    const double x = world.people[0].pose.x;
    if (entered < 0.0 && x >= 5.0) entered = t * dt;
    if (left < 0.0 && x >= 45.0) left = t * dt;
  }
  REQUIRE(left > 0.0);
  const double mean_speed = 40.0 / (left - entered);
  CHECK(mean_speed == Approx(desired).epsilon(0.10));
  WARN("lone walker: mean " << mean_speed << " m/s, desired " << desired << " m/s");
}

TEST_CASE("a person's route goes around a shelf between start and goal") {
  // 12 x 8 m; a shelf 1 m thick from the bottom wall up to y = 6 at x = 5.5..6.5.
  World world = walled_world(12.0, 8.0, 0.1, {{5.5, 0.0, 1.0, 6.0}});
  const Eigen::Vector2d start(2, 2);
  const Eigen::Vector2d goal(10, 2);
  CrowdSpec spec;
  spec.count = 1;
  spec.routes = {{start, goal}};
  Crowd crowd(world, spec);
  world.people = crowd.spawn();
  double nearest = 1e9;
  for (int t = 0; t < 60 * 40; ++t) {
    tick(crowd, world, 1.0 / 60.0);
    check_people_clear_of_walls(world);
    nearest = std::min(nearest, (Eigen::Vector2d(world.people[0].pose.x, world.people[0].pose.y) - goal).norm());
  }
  CHECK(nearest < 0.3);
  CHECK(crowd.goals_reached(0) >= 1);
}

TEST_CASE("a person heading at the standing avatar walks around it with a gap") {
  World world = walled_world(20.0, 10.0, 0.25);
  world.avatar.pose = {10.0, 5.0, 0.0};
  Crowd crowd = walkers_to(world, {{3, 5}}, {{17, 5}});
  double closest = 1e9;
  for (int t = 0; t < 60 * 20; ++t) {
    tick(crowd, world, 1.0 / 60.0);
    closest = std::min(closest, std::hypot(world.people[0].pose.x - 10.0, world.people[0].pose.y - 5.0));
  }
  CHECK(closest > 0.25 + 0.25 + 0.1);  // body radii plus a gap
  CHECK(world.people[0].pose.x == Approx(17.0).margin(0.3));
  WARN("avatar: closest centre distance " << closest << " m");
}
