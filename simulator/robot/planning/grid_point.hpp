// SPDX-License-Identifier: GPL-2.0-or-later
// on_grid: whether a world point lies on a costmap, checked in floating point before any cell index exists,
// so that absurd (huge but finite) coordinates from callers cannot overflow an int.
#pragma once

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// Whether world point (x, y) (m) lies on `grid`; false for NaN. When true, grid.cell_of(x, y) is in bounds.
inline bool on_grid(const CostmapGrid& grid, double x, double y) {
  const double col = (x - grid.origin_x) / grid.resolution;
  const double row = (y - grid.origin_y) / grid.resolution;
  return col >= 0.0 && row >= 0.0 && col < grid.width && row < grid.height;
}

}  // namespace rfbsim::sim
