// SPDX-License-Identifier: GPL-2.0-or-later
// LikelihoodField: the map's exact distance transform (DistanceField), capped and kept as a flat array.
#include "robot/sensing/likelihood_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "map/distance_field.hpp"

namespace rfbsim::sim {

LikelihoodField::LikelihoodField(const GridMap& map, double max_dist) : max_dist_(max_dist) {
  if (!(max_dist > 0.0) || !std::isfinite(max_dist)) {
    throw std::invalid_argument("LikelihoodField: laser_likelihood_max_dist must be a positive number of metres");
  }
  geometry_ = map;
  geometry_.occupied.clear();
  geometry_.occupied.shrink_to_fit();
  const DistanceField field(map);
  distances_.resize(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height));
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      distances_[static_cast<std::size_t>(row) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(col)] =
          static_cast<float>(std::min(field.at_cell({col, row}), max_dist));
    }
  }
}

double LikelihoodField::at_cell(int col, int row) const {
  if (col < 0 || row < 0 || col >= geometry_.width || row >= geometry_.height) return max_dist_;
  return distances_[static_cast<std::size_t>(row) * static_cast<std::size_t>(geometry_.width) +
                    static_cast<std::size_t>(col)];
}

double LikelihoodField::at(double x, double y) const {
  // Bounds in the map frame first, so that huge or NaN coordinates never reach an int cast.
  const Eigen::Vector2d p = geometry_.to_map_frame(x, y) / geometry_.resolution;
  if (!(p.x() >= 0.0 && p.y() >= 0.0 && p.x() < geometry_.width && p.y() < geometry_.height)) return max_dist_;
  return at_cell(static_cast<int>(p.x()), static_cast<int>(p.y()));
}

}  // namespace rfbsim::sim
