// SPDX-License-Identifier: GPL-2.0-or-later
// Small maps and a scripted drive for the sensing tests: walled rooms with blocks, and a unicycle that
// moves the true pose through a list of (speed, turn rate, duration) segments.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "map/grid_map.hpp"
#include "world/world.hpp"

namespace rfbsim::sim::test {

/// A block of wall, world metres (lower-left corner and size).
using Block = WallBlock;

/// A `width` x `height` m map with a one-cell wall all round and the given blocks (cells whose centre lies
/// inside a block), on a `res` grid with its origin at (0, 0).
inline GridMap walled_room(double width, double height, double res, const std::vector<Block>& blocks = {}) {
  return walled_grid(width, height, res, blocks);
}

/// An 8 x 6 m room at 0.05 m with boxes, a pillar and wall stubs placed without symmetry, so that a lidar
/// pins the pose down everywhere along `drive_segments()`.
inline GridMap feature_room() {
  return walled_room(8.0, 6.0, 0.05,
                     {
                         {1.5, 4.0, 0.8, 0.6},   // a crate north-west
                         {5.0, 1.0, 0.4, 1.2},   // a cabinet south-east
                         {6.5, 4.0, 0.2, 2.0},   // a wall stub from the north wall
                         {2.6, 3.0, 0.3, 0.3},   // a pillar
                         {0.0, 1.0, 1.2, 0.2},   // a wall stub from the west wall
                     });
}

/// A piece of the scripted drive: forward speed (m/s), turn rate (rad/s), duration (s).
struct Segment {
  double v = 0.0;
  double w = 0.0;
  double seconds = 0.0;
};

/// The drive through feature_room() from (1.2, 2.0, 0): 2 m east, a quarter circle left (r 0.5 m), 1 m
/// north, a quarter turn right in place, 1 m east: about 4.8 m and two turns.
inline std::vector<Segment> drive_segments() {
  return {{0.4, 0.0, 5.0},
          {0.4, 0.8, std::numbers::pi / 2 / 0.8},
          {0.4, 0.0, 2.5},
          {0.0, -1.0, std::numbers::pi / 2},
          {0.4, 0.0, 2.5}};
}

/// The true poses of driving `segments` from `start` at `hz` ticks per second (exact arcs), start excluded.
inline std::vector<Pose2> drive(const Pose2& start, const std::vector<Segment>& segments, double hz) {
  std::vector<Pose2> poses;
  Pose2 pose = start;
  const double dt = 1.0 / hz;
  for (const Segment& segment : segments) {
    const int ticks = static_cast<int>(std::lround(segment.seconds * hz));
    for (int i = 0; i < ticks; ++i) {
      const double turn = segment.w * dt;
      if (std::abs(turn) < 1e-12) {
        pose.x += segment.v * dt * std::cos(pose.yaw);
        pose.y += segment.v * dt * std::sin(pose.yaw);
      } else {
        const double r = segment.v / segment.w;
        pose.x += r * (std::sin(pose.yaw + turn) - std::sin(pose.yaw));
        pose.y -= r * (std::cos(pose.yaw + turn) - std::cos(pose.yaw));
      }
      pose.yaw += turn;
      poses.push_back(pose);
    }
  }
  return poses;
}

}  // namespace rfbsim::sim::test
