// SPDX-License-Identifier: GPL-2.0-or-later
// The cost of one physics tick in a warehouse-sized scene; hidden ([.]): run it by its tag "[bench]".
// It prints the time and asserts nothing about it (machines differ).
#include "physics/physics_world.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

using namespace rfbsim::sim;

namespace {

// 20 m x 30 m at 0.5 m: a border and 36 short wall pieces, so about 40 wall rectangles.
GridMap warehouse_map() {
  GridMap map;
  map.width = 40;
  map.height = 60;
  map.resolution = 0.5;
  map.occupied.assign(static_cast<std::size_t>(map.width * map.height), 0);
  auto block = [&map](int col, int row) { map.occupied[static_cast<std::size_t>(row * map.width + col)] = 1; };
  for (int col = 0; col < map.width; ++col) {
    block(col, 0);
    block(col, map.height - 1);
  }
  for (int row = 0; row < map.height; ++row) {
    block(0, row);
    block(map.width - 1, row);
  }
  for (int k = 0; k < 36; ++k) {
    const int row = 4 + (k % 9) * 6;
    const int col = 3 + (k / 9) * 9;
    for (int i = 0; i < 4; ++i) block(col + i, row);
  }
  return map;
}

}  // namespace

TEST_CASE("step time: avatar, 15 people and the robot among 40 walls and 30 props", "[.][bench]") {
  World w;
  w.map = warehouse_map();
  // 30 crates in a 5 x 6 lattice between the wall pieces.
  for (int i = 0; i < 30; ++i) {
    Prop crate;
    crate.x = 2.0 + (i % 5) * 4.0;
    crate.y = 3.8 + (i / 5) * 4.5;
    crate.size_x = 0.8;
    crate.size_y = 0.6;
    crate.yaw = 0.1 * i;
    w.props.push_back(crate);
  }
  for (int i = 0; i < 15; ++i) {
    Person p;
    p.pose = {1.5 + (i % 5) * 4.0, 2.0 + (i / 5) * 9.0, 0.0};
    w.people.push_back(p);
  }
  w.robot = Robot{};
  w.robot->pose = {10.0, 15.0, 0.0};
  w.avatar.pose = {9.0, 15.0, 0.0};
  const auto rectangles = merge_wall_rectangles(w.map);

  PhysicsWorld physics(w);
  constexpr double kDt = 1.0 / 60.0;
  constexpr int kTicks = 3600;
  double total_ms = 0.0;
  double worst_ms = 0.0;
  std::size_t contacts = 0;
  for (int tick = 0; tick < kTicks; ++tick) {
    // Everyone walks in slowly turning directions, so they meet walls, crates and each other.
    const double t = tick * kDt;
    w.avatar.speed = 1.3;
    w.avatar.pose.yaw = std::sin(0.3 * t);
    for (std::size_t i = 0; i < w.people.size(); ++i) {
      const double angle = 0.4 * t + static_cast<double>(i);
      w.people[i].velocity = 1.2 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    w.robot->velocity = Eigen::Vector2d(0.4 * std::cos(0.2 * t), 0.4 * std::sin(0.2 * t));
    const auto start = std::chrono::steady_clock::now();
    physics.step(w, kDt);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    total_ms += ms;
    worst_ms = std::max(worst_ms, ms);
    contacts += w.contacts.size();
    ++w.tick;
  }
  std::cout << "physics step: " << rectangles.size() << " wall rectangles, " << w.props.size() << " props, "
            << w.people.size() << " people + avatar + robot: mean " << total_ms / kTicks << " ms, worst "
            << worst_ms << " ms over " << kTicks << " ticks; " << contacts << " contact events\n";
  CHECK(contacts > 0);
}
