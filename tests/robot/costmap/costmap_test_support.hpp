// SPDX-License-Identifier: GPL-2.0-or-later
// Helpers for the costmap tests: small rooms, scans, people, and the master costs worked out by brute force
// from the formulas, to compare the incremental LayeredCostmap against.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <vector>

#include "robot/costmap/layered_costmap.hpp"

namespace rfbsim::sim::costmap_test {

/// A quiet NaN, for the tests of bad input.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A room of cols x rows cells at `res` with walls on its border and wall cells at `inner`.
inline GridMap room(int cols, int rows, double res, std::initializer_list<Cell> inner = {}) {
  GridMap map;
  map.width = cols;
  map.height = rows;
  map.resolution = res;
  map.occupied.assign(static_cast<std::size_t>(cols * rows), 0);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (col == 0 || row == 0 || col == cols - 1 || row == rows - 1) {
        map.occupied[static_cast<std::size_t>(row * cols + col)] = 1;
      }
    }
  }
  for (const Cell& c : inner) map.occupied[static_cast<std::size_t>(c.row * cols + c.col)] = 1;
  return map;
}

// A scan of the given beams, the first at `angle_min`, `increment` apart; 8 m range_max.
inline LaserScan scan(double angle_min, double increment, std::vector<float> ranges, double range_min = 0.12) {
  LaserScan s;
  s.angle_min = angle_min;
  s.angle_increment = increment;
  s.range_min = range_min;
  s.range_max = 8.0;
  s.ranges = std::move(ranges);
  return s;
}

// A person at (x, y) m moving at (vx, vy) m/s.
inline SeenPerson person_at(double x, double y, double vx = 0.0, double vy = 0.0) {
  SeenPerson p;
  p.position = {x, y};
  p.velocity = {vx, vy};
  return p;
}

// The costmap's obstacle layer, which these tests need on.
inline const ObstacleLayer& marks_of(const LayeredCostmap& costmap) {
  const ObstacleLayer* layer = costmap.obstacle_layer();
  if (layer == nullptr) throw std::logic_error("the obstacle layer is off");
  return *layer;
}

// docs/sources.md's inflation formula with the costmap's parameters.
inline int inflation_expected(double d, const CostmapParams& p) {
  if (d == 0.0) return 254;
  if (d > p.inflation.inflation_radius + 1e-9) return 0;
  if (d <= p.robot_radius + 1e-9) return 253;
  return static_cast<int>(std::floor(252.0 * std::exp(-p.inflation.cost_scaling_factor * (d - p.robot_radius))));
}

// The master costs worked out cell by cell, independently of the dirty windows and caches: the nearest
// lethal cell (a wall of the map, the map's outside, or an obstacle mark) within the inflation's reach,
// inflated; the max with the proxemic cost of every person.
inline CostmapGrid brute_force(const LayeredCostmap& costmap, const GridMap& map,
                               const std::vector<SeenPerson>& people) {
  const CostmapParams& p = costmap.params();
  CostmapGrid out = costmap.grid();
  const int reach = static_cast<int>(std::ceil(p.inflation.inflation_radius / p.resolution - 1e-9));
  for (int row = 0; row < out.height; ++row) {
    for (int col = 0; col < out.width; ++col) {
      double nearest = std::numeric_limits<double>::infinity();
      for (int dr = -reach; dr <= reach; ++dr) {
        for (int dc = -reach; dc <= reach; ++dc) {
          const Eigen::Vector2d c = out.cell_centre({col + dc, row + dr});
          if (map.is_occupied_at(c.x(), c.y()) || marks_of(costmap).is_marked_at(c.x(), c.y())) {
            nearest = std::min(nearest, p.resolution * std::hypot(dc, dr));
          }
        }
      }
      int cost = std::isinf(nearest) ? 0 : inflation_expected(nearest, p);
      for (const SeenPerson& person : people) {
        const double value = proxemic_value(person, out.cell_centre({col, row}), p.proxemic);
        cost = std::max<int>(cost, proxemic_cost(value, p.proxemic));
      }
      out.set({col, row}, static_cast<std::uint8_t>(cost));
    }
  }
  return out;
}

// How many cells of two same-sized grids differ.
inline int count_differences(const CostmapGrid& a, const CostmapGrid& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.costs.size(); ++i) n += a.costs[i] != b.costs[i] ? 1 : 0;
  return n;
}

}  // namespace rfbsim::sim::costmap_test
