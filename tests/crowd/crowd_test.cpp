// SPDX-License-Identifier: GPL-2.0-or-later
// Crowd: spawning (counts, draws, reproducibility), gait, determinism, and a ten-minute run in a room.
#include <catch2/catch.hpp>

#include <chrono>
#include <cstring>

#include "crowd_test_support.hpp"

using namespace rfbsim::sim;
using namespace rfbsim::sim::test;

namespace {

// The 20 x 30 m room of the long-run and timing tests: four shelves and six goals around them.
World room() {
  return walled_world(20.0, 30.0, 0.1, {{4, 6, 1, 6}, {10, 6, 1, 6}, {4, 18, 1, 6}, {14, 14, 2, 3}});
}

CrowdSpec room_crowd(std::uint64_t seed) {
  CrowdSpec spec;
  spec.count = 15;
  spec.goals = {{2, 2}, {18, 2}, {2, 28}, {18, 28}, {8, 15}, {12, 24}};
  spec.seed = seed;
  return spec;
}

// FNV-1a over the bytes of every pose and velocity: equal hashes <=> bit-identical states (in practice).
std::uint64_t state_hash(const World& world) {
  std::uint64_t h = 1469598103934665603ULL;
  const auto mix = [&h](double v) {
    unsigned char bytes[sizeof v];
    std::memcpy(bytes, &v, sizeof v);
    for (const unsigned char b : bytes) h = (h ^ b) * 1099511628211ULL;
  };
  for (const Person& p : world.people) {
    mix(p.pose.x);
    mix(p.pose.y);
    mix(p.pose.yaw);
    mix(p.velocity.x());
    mix(p.velocity.y());
    mix(p.gait_phase);
  }
  return h;
}

}  // namespace

TEST_CASE("spawn: count, ids, clamped speed draws with the asked mean and spread, bodies apart") {
  const World world = walled_world(40.0, 40.0, 0.5);
  CrowdSpec spec;
  spec.count = 500;
  spec.seed = 7;
  const Crowd crowd(world, spec);
  const std::vector<Person> people = crowd.spawn();
  REQUIRE(people.size() == 500);
  double sum = 0.0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < people.size(); ++i) {
    const Person& p = people[i];
    CHECK(p.id == static_cast<int>(i) + 1);
    CHECK(p.desired_speed >= 0.5);
    CHECK(p.desired_speed <= 2.0);
    CHECK(p.height >= 1.55);
    CHECK(p.height <= 1.95);
    CHECK_FALSE(world.obstacles.disc_hits_wall(p.pose.x, p.pose.y, p.radius));
    sum += p.desired_speed;
    sum_sq += p.desired_speed * p.desired_speed;
  }
  const double mean = sum / 500.0;
  const double std_dev = std::sqrt(sum_sq / 500.0 - mean * mean);
  // Three standard errors: 0.26 / sqrt(500) = 0.012 for the mean, about 0.008 for the spread.
  CHECK(mean == Approx(1.34).margin(0.035));
  CHECK(std_dev == Approx(0.26).margin(0.025));
  // No two bodies overlap.
  for (std::size_t i = 0; i < people.size(); ++i) {
    for (std::size_t j = i + 1; j < people.size(); ++j) {
      const double d = std::hypot(people[i].pose.x - people[j].pose.x, people[i].pose.y - people[j].pose.y);
      if (d <= people[i].radius + people[j].radius) FAIL("people " << i << " and " << j << " overlap");
    }
  }
}

TEST_CASE("spawn: the same seed gives the same people, another seed others, one more person changes none") {
  const World world = walled_world(20.0, 30.0, 0.25);
  CrowdSpec spec = room_crowd(3);
  const std::vector<Person> a = Crowd(world, spec).spawn();
  const std::vector<Person> b = Crowd(world, spec).spawn();
  spec.seed = 4;
  const std::vector<Person> other = Crowd(world, spec).spawn();
  spec.seed = 3;
  spec.count = 16;
  const std::vector<Person> more = Crowd(world, spec).spawn();
  int differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].pose.x == b[i].pose.x);
    CHECK(a[i].pose.y == b[i].pose.y);
    CHECK(a[i].pose.yaw == b[i].pose.yaw);
    CHECK(a[i].desired_speed == b[i].desired_speed);
    CHECK(a[i].rgb == b[i].rgb);
    CHECK(a[i].pose.x == more[i].pose.x);
    CHECK(a[i].desired_speed == more[i].desired_speed);
    CHECK(a[i].height == more[i].height);
    if (a[i].desired_speed != other[i].desired_speed || a[i].pose.x != other[i].pose.x) ++differing;
  }
  CHECK(differing == 15);
}

TEST_CASE("spawn on routes: everyone starts on their route") {
  const World world = walled_world(20.0, 10.0, 0.25);
  CrowdSpec spec;
  spec.count = 6;
  spec.routes = {{{2, 3}, {18, 3}}, {{3, 7}, {17, 7}}};
  const std::vector<Person> people = Crowd(world, spec).spawn();
  for (std::size_t i = 0; i < people.size(); ++i) {
    const double y = i % 2 == 0 ? 3.0 : 7.0;
    // On the route, or moved sideways by at most 1 m where the route was crowded.
    CHECK(std::abs(people[i].pose.y - y) <= 1.0);
  }
}

TEST_CASE("gait: one cycle per 0.8 * height walked, wrapped") {
  Person p;
  p.height = 1.75;
  advance_gait(p, 0.35);  // a quarter stride
  CHECK(p.gait_phase == Approx(std::numbers::pi / 2));
  advance_gait(p, 1.4);  // a full stride more
  CHECK(p.gait_phase == Approx(std::numbers::pi / 2));
  World world;
  world.people = {p};
  world.people[0].velocity = {1.4, 0.0};
  move_people_freely(world, 0.25);
  CHECK(world.people[0].pose.x == Approx(0.35));
  CHECK(world.people[0].gait_phase == Approx(std::numbers::pi));
}

TEST_CASE("determinism: two crowds stepped 1000 ticks from the same seed are bit-identical") {
  std::uint64_t hashes[2] = {0, 0};
  World worlds[2] = {room(), room()};
  for (int run = 0; run < 2; ++run) {
    Crowd crowd(worlds[run], room_crowd(11));
    worlds[run].people = crowd.spawn();
    for (int t = 0; t < 1000; ++t) tick(crowd, worlds[run], 1.0 / 60.0);
    hashes[run] = state_hash(worlds[run]);
  }
  CHECK(hashes[0] == hashes[1]);
  for (std::size_t i = 0; i < worlds[0].people.size(); ++i) {
    CHECK(worlds[0].people[i].pose.x == worlds[1].people[i].pose.x);
    CHECK(worlds[0].people[i].pose.y == worlds[1].people[i].pose.y);
    CHECK(worlds[0].people[i].pose.yaw == worlds[1].people[i].pose.yaw);
  }
  // And they did walk.
  const std::vector<Person> start = Crowd(room(), room_crowd(11)).spawn();
  CHECK(std::hypot(worlds[0].people[0].pose.x - start[0].pose.x, worlds[0].people[0].pose.y - start[0].pose.y) > 1.0);
}

TEST_CASE("ten minutes of 15 people in a 20 x 30 m room: no NaN, nobody in a wall or off the map") {
  World world = room();
  Crowd crowd(world, room_crowd(5));
  world.people = crowd.spawn();
  const double dt = 0.05;
  double step_seconds = 0.0;
  int goals = 0;
  for (int t = 0; t < 12000; ++t) {
    const auto before = std::chrono::steady_clock::now();
    crowd.step(world, dt);
    step_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
    move_people_freely(world, dt);
    ++world.tick;
    check_people_clear_of_walls(world);
  }
  for (std::size_t i = 0; i < world.people.size(); ++i) goals += crowd.goals_reached(i);
  // Walking between six goals 2..26 m apart for 600 s, each person reaches many.
  CHECK(goals > 15 * 10);
  WARN("Crowd::step, 15 people, 20 x 30 m room at 0.1 m: " << step_seconds / 12000.0 * 1e6
                                                           << " us per tick; goals reached: " << goals);
}
