// SPDX-License-Identifier: GPL-2.0-or-later
// DistanceGrid: how far every cell of the local costmap is from a set of target cells, walking around
// obstacles (ROS base_local_planner's MapGrid, with 8-connected chamfer distances instead of 4-connected steps).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// Distances (m) over one costmap from target cells; reuses its buffers between computations.
class DistanceGrid {
 public:
  /// Unreachable cells, and points off the grid, read this.
  static constexpr float kUnreachable = std::numeric_limits<float>::infinity();

  /// Fills the grid with each cell's shortest 8-connected distance to the nearest of `targets` (cell indices
  /// into `grid`, duplicates allowed): a straight step counts one cell length, a diagonal one 1.4 (the 10/14
  /// chamfer, within 1 % of the straight-line distance, exact in integers). Walks only through cells cheaper
  /// than inscribed (253), with no diagonal step past a corner of such a cell. Targets in such cells are
  /// ignored (ROS starts from them too, which draws the robot's nose toward a person standing on the path
  /// and traps it facing them).
  void compute(const CostmapGrid& grid, const std::vector<std::int32_t>& targets);

  /// The distance (m) at a cell, kUnreachable if unreachable or off the grid.
  [[nodiscard]] float at(Cell c) const {
    if (c.col < 0 || c.row < 0 || c.col >= width_ || c.row >= height_) return kUnreachable;
    const std::uint32_t units =
        units_[static_cast<std::size_t>(c.row) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(c.col)];
    return units == kNone ? kUnreachable : static_cast<float>(units) * metres_per_unit_;
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::uint32_t kStraight = 10;  // units per straight step
  static constexpr std::uint32_t kDiagonal = 14;  // units per diagonal step
  int width_ = 0;
  int height_ = 0;
  float metres_per_unit_ = 0.0f;
  std::vector<std::uint32_t> units_;  // distance in tenths of a cell, kNone unreachable
  // Dial's bucket queue: with integer steps of 10 and 14, cells at distance d wait in bucket d mod 15.
  std::vector<std::int32_t> buckets_[kDiagonal + 1];
};

}  // namespace rfbsim::sim
