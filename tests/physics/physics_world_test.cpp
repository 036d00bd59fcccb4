// SPDX-License-Identifier: GPL-2.0-or-later
// PhysicsWorld: walls and props stop bodies, bodies slide, the avatar pushes the robot and the robot cannot
// push a person, contacts become events once per touch, and two worlds step bit for bit alike.
#include "physics/physics_world.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace rfbsim::sim;

namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr double kWalk = 1.3;  // m/s

// A 10 m x 8 m room of 1 m cells: the free inside is x in [1, 9], y in [1, 7].
World room() {
  World w;
  w.map = grid_from_text({"##########",
                          "#........#",
                          "#........#",
                          "#........#",
                          "#........#",
                          "#........#",
                          "#........#",
                          "##########"},
                         1.0);
  return w;
}

World avatar_in_room(double x, double y, double yaw, double speed = 0.0) {
  World w = room();
  w.avatar.pose = {x, y, yaw};
  w.avatar.speed = speed;
  return w;
}

Person person_at(double x, double y, Eigen::Vector2d velocity = Eigen::Vector2d::Zero()) {
  Person p;
  p.pose = {x, y, 0.0};
  p.velocity = velocity;
  return p;
}

// Steps `ticks` ticks with the avatar wanting `speed` (as its controller would set it every tick); returns
// every contact event on the way.
std::vector<ContactEvent> walk(PhysicsWorld& physics, World& w, int ticks, double speed) {
  std::vector<ContactEvent> events;
  for (int i = 0; i < ticks; ++i) {
    w.avatar.speed = speed;
    physics.step(w, kDt);
    events.insert(events.end(), w.contacts.begin(), w.contacts.end());
    ++w.tick;
  }
  return events;
}

int count(const std::vector<ContactEvent>& events, Party a, Party b) {
  int n = 0;
  for (const ContactEvent& e : events) n += e.a == a && e.b == b ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("free walking: the avatar holds its commanded speed and moves speed * t") {
  World w = avatar_in_room(2.0, 4.0, 0.0, kWalk);
  PhysicsWorld physics(w);
  walk(physics, w, 120, kWalk);
  CHECK(w.avatar.speed == Approx(kWalk).epsilon(0.02));
  CHECK(w.avatar.pose.x == Approx(2.0 + kWalk * 2.0).margin(1e-6));
  CHECK(w.avatar.pose.y == Approx(4.0).margin(1e-9));
  CHECK(w.avatar.distance_walked == Approx(kWalk * 2.0).margin(1e-6));
  // Gait: one cycle per 1.4 m stride.
  const double two_pi = 2.0 * std::numbers::pi;
  CHECK(w.avatar.gait_phase == Approx(std::fmod(kWalk * 2.0 / 1.4 * two_pi, two_pi)).margin(1e-5));
  CHECK(w.contacts.empty());
}

TEST_CASE("from rest the legs' bounded force sets the acceleration") {
  World w = avatar_in_room(2.0, 4.0, 0.0);
  PhysicsWorld physics(w);
  walk(physics, w, 1, kWalk);
  // 300 N on 70 kg for one tick.
  CHECK(w.avatar.speed == Approx(300.0 / 70.0 * kDt).epsilon(1e-6));
  walk(physics, w, 29, kWalk);
  CHECK(w.avatar.speed == Approx(kWalk).epsilon(0.02));
}

TEST_CASE("the avatar walking into a wall stops at it and reports one avatar-static contact") {
  World w = avatar_in_room(6.0, 4.0, 0.0, kWalk);
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  double closest = 0.0;
  for (int i = 0; i < 300; ++i) {
    const auto step_events = walk(physics, w, 1, kWalk);
    events.insert(events.end(), step_events.begin(), step_events.end());
    closest = std::max(closest, w.avatar.pose.x);
  }
  // The east wall's face is at x = 9; the avatar's radius is 0.25 m.
  CHECK(closest <= 9.0 - 0.25 + 0.02);
  // Leaning on the wall it rests in the 5 mm surface layer plus 300 N / 2e5 N/m.
  CHECK(w.avatar.pose.x == Approx(8.75 + 0.0065).margin(0.001));
  CHECK(std::abs(w.avatar.speed) < 0.01);
  REQUIRE(events.size() == 1);
  CHECK(events[0].a == Party::Avatar);
  CHECK(events[0].b == Party::Static);
  CHECK(events[0].impulse > 0.5);
  // It touched at (9 - 0.25 - 6) / 1.3 s = tick 127 (0-based), give or take the sub-step.
  CHECK(events[0].tick >= 125);
  CHECK(events[0].tick <= 128);

  // Backing off separates it; walking in again is a new touch.
  events = walk(physics, w, 60, -kWalk);
  CHECK(events.empty());
  events = walk(physics, w, 120, kWalk);
  CHECK(count(events, Party::Avatar, Party::Static) == 1);
}

TEST_CASE("walking diagonally into a wall the avatar slides along it") {
  World w = avatar_in_room(7.5, 1.6, std::numbers::pi / 4.0, kWalk);
  PhysicsWorld physics(w);
  walk(physics, w, 180, kWalk);
  // It met the east wall after 1.2 m along x; along y it kept the wanted 1.3 * sin 45 deg all the time.
  CHECK(w.avatar.pose.x == Approx(8.75).margin(0.02));
  CHECK(w.avatar.pose.y == Approx(1.6 + kWalk * std::sin(std::numbers::pi / 4.0) * 3.0).margin(0.02));
}

TEST_CASE("the avatar cannot walk through a prop") {
  World w = avatar_in_room(3.0, 4.0, 0.0, kWalk);
  Prop crate;
  crate.x = 6.0;
  crate.y = 4.0;
  crate.size_x = 1.0;
  crate.size_y = 1.0;
  w.props.push_back(crate);
  PhysicsWorld physics(w);
  const auto events = walk(physics, w, 240, kWalk);
  // The crate's face is at x = 5.5.
  CHECK(w.avatar.pose.x == Approx(5.5 - 0.25).margin(0.02));
  CHECK(count(events, Party::Avatar, Party::Static) == 1);
}

TEST_CASE("the avatar cannot walk through a person standing still") {
  World w = avatar_in_room(3.0, 4.0, 0.0, kWalk);
  w.people.push_back(person_at(6.0, 4.0));
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  double bumped_to = 0.0;
  for (int i = 0; i < 300; ++i) {
    w.people[0].velocity = Eigen::Vector2d::Zero();  // the crowd wants them to stand
    const auto step_events = walk(physics, w, 1, kWalk);
    events.insert(events.end(), step_events.begin(), step_events.end());
    if (i == 179) bumped_to = w.people[0].pose.x;
  }
  // The impact shoves the person a little; then their braced legs (450 N) outlast the avatar's push (300 N).
  CHECK(w.people[0].pose.x - 6.0 < 0.25);
  CHECK(w.people[0].pose.x == Approx(bumped_to).margin(0.001));  // still for the last 2 s
  CHECK(w.people[0].velocity.norm() < 0.01);
  CHECK(w.people[0].pose.x - w.avatar.pose.x > 0.5 - 0.02);  // the bodies meet at 0.25 + 0.25 m
  REQUIRE(count(events, Party::Avatar, Party::Person) == 1);
  CHECK(events[0].a_index == 0);
  CHECK(events[0].b_index == 0);
}

TEST_CASE("walking into the standing robot for 3 s pushes it, with one avatar-robot event") {
  World w = avatar_in_room(4.0, 4.0, 0.0, kWalk);
  w.robot = Robot{};
  w.robot->pose = {4.6, 4.0, 0.0};
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  for (int i = 0; i < 180; ++i) {
    w.robot->velocity = Eigen::Vector2d::Zero();  // its controller wants it to stand
    const auto step_events = walk(physics, w, 1, kWalk);
    events.insert(events.end(), step_events.begin(), step_events.end());
  }
  INFO("robot x " << w.robot->pose.x << ", avatar x " << w.avatar.pose.x);
  CHECK(w.robot->pose.x - 4.6 > 0.3);
  CHECK(w.avatar.pose.x < w.robot->pose.x - 0.41 + 0.02);  // pushes, does not pass through
  REQUIRE(count(events, Party::Avatar, Party::Robot) == 1);
  CHECK(events[0].impulse > 0.5);
}

TEST_CASE("the robot driving into a person stalls and reports one person-robot contact") {
  World w = avatar_in_room(2.0, 2.0, 0.0);
  w.people.push_back(person_at(8.0, 6.0));
  w.people.push_back(person_at(5.0, 4.0));
  w.robot = Robot{};
  w.robot->pose = {3.5, 4.0, 0.0};
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  for (int i = 0; i < 180; ++i) {
    w.robot->velocity = Eigen::Vector2d(0.5, 0.0);
    w.robot->yaw_rate = 0.1;
    w.people[0].velocity = w.people[1].velocity = Eigen::Vector2d::Zero();
    const auto step_events = walk(physics, w, 1, 0.0);
    events.insert(events.end(), step_events.begin(), step_events.end());
  }
  CHECK(std::abs(w.people[1].pose.x - 5.0) < 0.02);  // 40 N of wheels against 300 N of legs
  CHECK(w.robot->pose.x == Approx(5.0 - 0.25 - 0.16).margin(0.02));
  CHECK(w.robot->pose.yaw == Approx(0.1 * 3.0).margin(1e-9));  // its own yaw rate, not ODE's
  REQUIRE(events.size() == 1);
  CHECK(events[0].a == Party::Person);
  CHECK(events[0].a_index == 1);
  CHECK(events[0].b == Party::Robot);
}

TEST_CASE("a person walking into a wall reports one person-static contact with their index") {
  World w = avatar_in_room(2.0, 2.0, 0.0);
  w.people.push_back(person_at(3.0, 6.0));
  w.people.push_back(person_at(7.0, 4.0, {kWalk, 0.0}));
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  for (int i = 0; i < 180; ++i) {
    w.people[1].velocity = Eigen::Vector2d(kWalk, 0.0);
    const auto step_events = walk(physics, w, 1, 0.0);
    events.insert(events.end(), step_events.begin(), step_events.end());
  }
  CHECK(w.people[1].pose.x == Approx(9.0 - 0.25).margin(0.02));
  REQUIRE(events.size() == 1);
  CHECK(events[0].a == Party::Person);
  CHECK(events[0].a_index == 1);
  CHECK(events[0].b == Party::Static);
}

TEST_CASE("two people walking into each other: one person-person event") {
  World w = avatar_in_room(2.0, 2.0, 0.0);
  w.people.push_back(person_at(4.0, 4.0));
  w.people.push_back(person_at(6.0, 4.0));
  PhysicsWorld physics(w);
  std::vector<ContactEvent> events;
  for (int i = 0; i < 120; ++i) {
    w.people[0].velocity = Eigen::Vector2d(1.0, 0.0);
    w.people[1].velocity = Eigen::Vector2d(-1.0, 0.0);
    const auto step_events = walk(physics, w, 1, 0.0);
    events.insert(events.end(), step_events.begin(), step_events.end());
  }
  CHECK(w.people[1].pose.x - w.people[0].pose.x == Approx(0.5).margin(0.02));
  REQUIRE(events.size() == 1);
  CHECK((events[0].a == Party::Person && events[0].a_index == 0));
  CHECK((events[0].b == Party::Person && events[0].b_index == 1));
}

namespace {

// A busy little scene: three people crossing, a crate, the robot driving around, the avatar turning.
World busy_world() {
  World w = avatar_in_room(2.0, 2.0, 0.3, 0.0);
  Prop crate;
  crate.x = 5.0;
  crate.y = 4.0;
  crate.yaw = 0.4;
  w.props.push_back(crate);
  w.people.push_back(person_at(3.0, 5.0));
  w.people.push_back(person_at(7.0, 5.0));
  w.people.push_back(person_at(5.0, 2.0));
  w.robot = Robot{};
  w.robot->pose = {6.0, 3.0, 0.0};
  return w;
}

void script_inputs(World& w, int i) {
  const double t = i * kDt;
  w.avatar.speed = kWalk;
  w.avatar.pose.yaw = 0.3 + 0.8 * std::sin(0.7 * t);
  w.people[0].velocity = Eigen::Vector2d(1.2 * std::cos(0.5 * t), -0.4);
  w.people[1].velocity = Eigen::Vector2d(-1.1, 0.3 * std::sin(t));
  w.people[2].velocity = Eigen::Vector2d(0.2, 1.0 * std::cos(0.3 * t));
  w.robot->velocity = Eigen::Vector2d(0.4 * std::cos(t), 0.4 * std::sin(t));
  w.robot->yaw_rate = 1.0;
}

std::vector<double> poses(const World& w) {
  std::vector<double> out{w.avatar.pose.x, w.avatar.pose.y, w.avatar.speed, w.avatar.gait_phase};
  for (const Person& p : w.people) out.insert(out.end(), {p.pose.x, p.pose.y, p.velocity.x(), p.velocity.y()});
  out.insert(out.end(), {w.robot->pose.x, w.robot->pose.y, w.robot->pose.yaw});
  for (const ContactEvent& e : w.contacts) out.insert(out.end(), {static_cast<double>(e.a), e.impulse});
  return out;
}

}  // namespace

TEST_CASE("two PhysicsWorlds stepped in turn give bit-identical poses for 600 ticks") {
  World w1 = busy_world();
  World w2 = busy_world();
  PhysicsWorld p1(w1);
  PhysicsWorld p2(w2);
  int contacts = 0;
  for (int i = 0; i < 600; ++i) {
    script_inputs(w1, i);
    script_inputs(w2, i);
    p1.step(w1, kDt);
    p2.step(w2, kDt);
    ++w1.tick;
    ++w2.tick;
    contacts += static_cast<int>(w1.contacts.size());
    REQUIRE(poses(w1) == poses(w2));  // exact equality, not Approx
  }
  CHECK(contacts > 0);  // the scene did exercise contacts
}
