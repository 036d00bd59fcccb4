// SPDX-License-Identifier: GPL-2.0-or-later
// LikelihoodField: for AMCL's laser model, the distance from every cell of the map to the nearest blocking
// cell, capped at laser_likelihood_max_dist, computed once when the map is loaded (as AMCL's map_update_cspace).
#pragma once

#include <vector>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

class LikelihoodField {
 public:
  LikelihoodField() = default;
  /// Distances on `map`'s grid (walls and props: the map the lidar sees), between cell centres, capped at
  /// `max_dist` m (> 0). The map's edge counts as wall, as it does for the lidar's ray cast.
  LikelihoodField(const GridMap& map, double max_dist);

  /// Metres from the centre of cell (col, row) to the nearest blocking cell's centre, at most max_dist;
  /// max_dist outside the grid (AMCL does the same for endpoints off the map).
  [[nodiscard]] double at_cell(int col, int row) const;
  /// The distance of the cell containing the world point (x, y), m.
  [[nodiscard]] double at(double x, double y) const;
  /// The per-cell distances, width * height, row-major from the bottom row, m.
  [[nodiscard]] const std::vector<float>& distances() const { return distances_; }
  /// The grid's geometry (its `occupied` is left empty to save memory).
  [[nodiscard]] const GridMap& geometry() const { return geometry_; }
  [[nodiscard]] double max_dist() const { return max_dist_; }

 private:
  GridMap geometry_;
  double max_dist_ = 2.0;
  std::vector<float> distances_;
};

}  // namespace rfbsim::sim
