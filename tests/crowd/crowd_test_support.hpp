// SPDX-License-Identifier: GPL-2.0-or-later
// Small worlds for the crowd tests: a walled rectangle with optional blocks, and the per-tick wall check.
#pragma once

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "crowd/crowd.hpp"

namespace rfbsim::sim::test {

/// A block of wall, world metres (lower-left corner and size).
using Block = WallBlock;

/// A world with a `width` x `height` m room: a one-cell wall border and the given blocks, on a `res` grid.
inline World walled_world(double width, double height, double res, const std::vector<Block>& blocks = {}) {
  const GridMap map = walled_grid(width, height, res, blocks);
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
