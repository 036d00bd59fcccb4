// SPDX-License-Identifier: GPL-2.0-or-later
// DistanceField: for every cell of a GridMap, the Euclidean distance to the nearest blocking cell, so
// that wall forces, clearance checks and route planning cost one lookup instead of a search.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

class DistanceField {
 public:
  DistanceField() = default;
  /// Exact Euclidean distance transform (Felzenszwalb and Huttenlocher's two-pass method), between cell
  /// centres, so a free cell next to a wall reads one resolution. Cells outside the map count as walls.
  explicit DistanceField(const GridMap& map);

  /// Metres from the centre of `c` to the nearest blocking cell's centre; 0 inside walls and outside.
  [[nodiscard]] double at_cell(Cell c) const;
  /// Distance at a world point to the nearest wall's surface, approximately: the bilinear interpolation
  /// of the cell values minus half a cell, never below 0.
  [[nodiscard]] double at(double x, double y) const;
  /// The world-frame direction in which the distance grows fastest at (x, y) (away from the nearest
  /// wall), unit length; zero where the field is flat.
  [[nodiscard]] Eigen::Vector2d gradient(double x, double y) const;
  [[nodiscard]] const GridMap& map() const { return map_; }

 private:
  [[nodiscard]] double interpolated(Eigen::Vector2d map_point) const;
  GridMap map_;
  std::vector<float> metres_;  // width * height, row-major from the bottom row
};

}  // namespace rfbsim::sim
