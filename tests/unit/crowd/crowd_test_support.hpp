// SPDX-License-Identifier: GPL-2.0-or-later
// Small worlds for the crowd tests: a walled rectangle with optional blocks, and the per-tick wall check.
#pragma once

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "crowd/crowd.hpp"

namespace rfbsim::sim::test {

/// A block of wall, world metres (lower-left corner and size).
struct Block {
  double x = 0.0;
  double y = 0.0;
  double w = 0.0;
  double h = 0.0;
};

/// A world with a `width` x `height` m room: a one-cell wall border and the given blocks, on a `res` grid.
inline World walled_world(double width, double height, double res, const std::vector<Block>& blocks = {}) {
  GridMap map;
  map.width = static_cast<int>(std::lround(width / res));
  map.height = static_cast<int>(std::lround(height / res));
  map.resolution = res;
  map.occupied.assign(static_cast<std::size_t>(map.width * map.height), 0);
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      bool wall = row == 0 || col == 0 || row == map.height - 1 || col == map.width - 1;
      const double x = (col + 0.5) * res;
      const double y = (row + 0.5) * res;
      for (const Block& b : blocks) wall = wall || (x > b.x && x < b.x + b.w && y > b.y && y < b.y + b.h);
      map.occupied[static_cast<std::size_t>(row * map.width + col)] = wall ? 1 : 0;
    }
  }
  World world;
  world.map = map;
  world.obstacles = map;
  world.avatar.pose = {-100.0, -100.0, 0.0};  // far off the map unless a test places it
  return world;
}

/// Every person's centre is outside wall cells, half its body clears every wall, and nothing is NaN.
inline void check_people_clear_of_walls(const World& world) {
  for (const Person& p : world.people) {
    INFO("person " << p.id << " at " << p.pose.x << ", " << p.pose.y << " tick " << world.tick);
    REQUIRE(std::isfinite(p.pose.x));
    REQUIRE(std::isfinite(p.pose.y));
    REQUIRE(std::isfinite(p.pose.yaw));
    REQUIRE(p.velocity.allFinite());
    REQUIRE(world.obstacles.contains(p.pose.x, p.pose.y));
    REQUIRE_FALSE(world.obstacles.is_occupied_at(p.pose.x, p.pose.y));
    REQUIRE_FALSE(world.obstacles.disc_hits_wall(p.pose.x, p.pose.y, 0.5 * p.radius));
  }
}

/// One tick without physics: the crowd decides, the people move.
inline void tick(Crowd& crowd, World& world, double dt) {
  crowd.step(world, dt);
  move_people_freely(world, dt);
  ++world.tick;
  world.time = static_cast<double>(world.tick) * dt;
}

}  // namespace rfbsim::sim::test
