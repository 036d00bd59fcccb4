// SPDX-License-Identifier: GPL-2.0-or-later
// The costmap frame's extent, from the corners of the static map.
#include "robot/costmap/costmap_frame.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace rfbsim::sim {

CostmapGrid frame_for_map(const GridMap& map, double resolution, int margin_cells) {
  if (!std::isfinite(map.origin_x) || !std::isfinite(map.origin_y) || !std::isfinite(map.origin_yaw) ||
      !(map.resolution > 0.0) || !std::isfinite(map.resolution) || map.width < 0 || map.height < 0) {
    throw std::invalid_argument("costmap: the static map's origin or resolution is not a finite number");
  }
  // The map's grid may be turned: take the world-axis-aligned box around its four corners.
  const double w = map.width * map.resolution;
  const double h = map.height * map.resolution;
  const std::array<Eigen::Vector2d, 4> corners{map.to_world({0.0, 0.0}), map.to_world({w, 0.0}),
                                               map.to_world({0.0, h}), map.to_world({w, h})};
  Eigen::Vector2d low = corners[0];
  Eigen::Vector2d high = corners[0];
  for (const Eigen::Vector2d& c : corners) {
    low = low.cwiseMin(c);
    high = high.cwiseMax(c);
  }
  // Whole cells covering the box; the small allowance keeps 20 m / 0.05 m at 400 cells, not 401.
  const auto cells = [resolution](double metres) {
    return std::max(1, static_cast<int>(std::ceil(metres / resolution - 1e-6)));
  };
  const int columns = cells(high.x() - low.x()) + 2 * margin_cells;
  const int rows = cells(high.y() - low.y()) + 2 * margin_cells;
  return CostmapGrid::sized(columns, rows, resolution, low.x() - margin_cells * resolution,
                            low.y() - margin_cells * resolution);
}

}  // namespace rfbsim::sim
