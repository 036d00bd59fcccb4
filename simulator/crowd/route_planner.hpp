// SPDX-License-Identifier: GPL-2.0-or-later
// RoutePlanner: a pedestrian's way between two points around shelves and walls: A* over blocks of cells of
// the obstacle map that keep a clearance from walls, shortened to a few waypoints a person can walk straight.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "map/distance_field.hpp"
#include "map/grid_map.hpp"

namespace rfbsim::sim {

/// How routes are planned (rfbsim choices).
struct RoutePlannerParams {
  double comfort_distance = 1.0;  ///< m: cells nearer than this to a wall cost more to walk through
  double wall_cost = 2.0;         ///< extra cost factor at a wall's surface, falling linearly to 0 at comfort
  double search_step = 0.2;       ///< m: the search steps between blocks of cells about this wide
};

/// A planned route: waypoints in world metres (the first leg starts where the person stands, which is not
/// included; the last waypoint is the goal), and the clearance (m) it keeps from walls.
struct PlannedRoute {
  std::vector<Eigen::Vector2d> waypoints;  ///< empty when no path exists at any clearance
  double clearance = 0.0;
};

/// Plans on one obstacle map; owns the map's distance field, built once.
class RoutePlanner {
 public:
  RoutePlanner() = default;
  explicit RoutePlanner(const GridMap& obstacles, RoutePlannerParams params = {});

  /// The way from `from` to `to` keeping `clearance` (m) between the body centre and wall surfaces; if
  /// there is none, half that, then any free cells. A goal inside a wall is moved to the nearest free cell.
  [[nodiscard]] PlannedRoute plan(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double clearance) const;
  /// Whether the straight segment a-b keeps `clearance` from walls (sampled every half cell); the cells of
  /// a and b themselves are exempt, so a route may start or end in a narrow spot.
  [[nodiscard]] bool line_clear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance) const;
  /// Whether cell `c` is free and its centre at least `clearance` (m) from the nearest wall's surface.
  [[nodiscard]] bool walkable(Cell c, double clearance) const;
  /// The nearest free cell centre to `p` (p itself when its cell is free), searching up to `max_cells` rings.
  [[nodiscard]] Eigen::Vector2d nearest_free(const Eigen::Vector2d& p, int max_cells = 20) const;
  [[nodiscard]] const DistanceField& field() const { return field_; }
  [[nodiscard]] const GridMap& map() const { return field_.map(); }

 private:
  [[nodiscard]] std::vector<Cell> search(Cell start, Cell goal, double clearance) const;
  DistanceField field_;
  RoutePlannerParams params_;
  int block_ = 1;                   // cells per side of the search's blocks
  std::vector<Cell> block_offsets_;  // a block's cells, nearest its middle first
};

}  // namespace rfbsim::sim
