// SPDX-License-Identifier: GPL-2.0-or-later
// CostmapGrid: a costmap_2d-style grid of one-byte costs on the floor plane, axis-aligned with the world.
// Cell (col, row) covers [origin_x + col*res, +res) x [origin_y + row*res, +res); row 0 is the bottom row.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

/// costmap_2d's cost classes (docs/sources.md, Costmap).
namespace cost {
inline constexpr std::uint8_t kFree = 0;
inline constexpr std::uint8_t kInscribed = 253;  ///< the footprint's centre here touches an obstacle
inline constexpr std::uint8_t kLethal = 254;     ///< an obstacle is in this cell
inline constexpr std::uint8_t kUnknown = 255;
}  // namespace cost

struct CostmapGrid {
  int width = 0;            ///< columns
  int height = 0;           ///< rows
  double resolution = 0.05; ///< m per cell
  double origin_x = 0.0;    ///< m, world position of the lower-left corner of cell (0, 0)
  double origin_y = 0.0;    ///< m
  std::vector<std::uint8_t> costs;  ///< width * height, row-major from the bottom row

  /// An all-free grid of the given size.
  static CostmapGrid sized(int width, int height, double resolution, double origin_x, double origin_y) {
    CostmapGrid grid;
    grid.width = width;
    grid.height = height;
    grid.resolution = resolution;
    grid.origin_x = origin_x;
    grid.origin_y = origin_y;
    grid.costs.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), cost::kFree);
    return grid;
  }

  [[nodiscard]] bool in_bounds(Cell c) const { return c.col >= 0 && c.row >= 0 && c.col < width && c.row < height; }
  /// The cell containing world point (x, y); may lie outside the grid.
  [[nodiscard]] Cell cell_of(double x, double y) const {
    return {static_cast<int>(std::floor((x - origin_x) / resolution)),
            static_cast<int>(std::floor((y - origin_y) / resolution))};
  }
  [[nodiscard]] Eigen::Vector2d cell_centre(Cell c) const {
    return {origin_x + (c.col + 0.5) * resolution, origin_y + (c.row + 0.5) * resolution};
  }
  [[nodiscard]] std::size_t index(Cell c) const {
    return static_cast<std::size_t>(c.row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c.col);
  }
  /// Cost of a cell; a cell outside the grid reads `outside` (lethal unless the caller says otherwise).
  [[nodiscard]] std::uint8_t at(Cell c, std::uint8_t outside = cost::kLethal) const {
    return in_bounds(c) ? costs[index(c)] : outside;
  }
  /// Cost at a world point (the cell containing it).
  [[nodiscard]] std::uint8_t at_world(double x, double y, std::uint8_t outside = cost::kLethal) const {
    return at(cell_of(x, y), outside);
  }
  void set(Cell c, std::uint8_t value) {
    if (in_bounds(c)) costs[index(c)] = value;
  }
};

}  // namespace rfbsim::sim
