// SPDX-License-Identifier: GPL-2.0-or-later
// ProxemicLayer: personal space as cost (Lu, Hershberger, Smart 2014; social_navigation_layers' proxemic
// layer). Around each person a Gaussian, stretched in the direction they walk (not behind them, which was
// the upstream layer's sign bug), so the robot keeps out of the way a person is going.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_grid.hpp"
#include "robot/costmap/costmap_params.hpp"
#include "robot/costmap/seen_person.hpp"

namespace rfbsim::sim {

/// The proxemic cost of `person` at world `point`, before cutoff and rounding: in the person's frame (x
/// along their velocity) amplitude * exp(-(x^2 / (2 sx^2) + y^2 / (2 sy^2))), with sx^2 = covariance *
/// (1 + factor * speed) in front (x > 0) of a person moving at least standing_speed, covariance elsewhere;
/// sy^2 = covariance.
double proxemic_value(const SeenPerson& person, const Eigen::Vector2d& point, const ProxemicLayerParams& params);

/// The cost a cell gets from that value: 0 below the cutoff, else floor(value) (the upstream layer's
/// integer cast), at most 252 so that personal space alone never reads as an obstacle.
std::uint8_t proxemic_cost(double value, const ProxemicLayerParams& params);

/// A world-axis-aligned box, m; empty when min > max.
struct WorldBox {
  Eigen::Vector2d min{1.0, 1.0};
  Eigen::Vector2d max{0.0, 0.0};
  [[nodiscard]] bool empty() const { return !(min.x() <= max.x() && min.y() <= max.y()); }
};

/// The smallest box around every point where proxemic_value reaches the cutoff, worked out from the
/// cutoff ellipses (a half ellipse in front, a half disc behind); empty if amplitude <= cutoff or the
/// person's position is not finite.
WorldBox proxemic_bounds(const SeenPerson& person, const ProxemicLayerParams& params);

class ProxemicLayer {
 public:
  /// No people yet.
  explicit ProxemicLayer(const ProxemicLayerParams& params) : params_(params) {}

  /// The people of this update (copied; people with a non-finite position are left out, a non-finite
  /// velocity counts as standing). Returns how many were kept.
  int set_people(std::span<const SeenPerson> people);
  /// The people set_people kept.
  [[nodiscard]] const std::vector<SeenPerson>& people() const { return people_; }

  /// Bounds: the cutoff boxes of this update's people and of the last update's (whose costs must go), as
  /// cells of `frame`.
  void update_bounds(const CostmapGrid& frame, CellWindow& frame_bounds);
  /// Rewrites `window` of `social` (the layer's own costs, the master's geometry): zero, then every
  /// person's Gaussian (each cell the max over people); then master = max(master, social) there.
  void update_costs(CostmapGrid& master, CostmapGrid& social, const CellWindow& window) const;

  /// Writes one person's costs into `grid` inside `clip`, each cell max(old, cost); visits only the cells
  /// whose centres lie in the person's proxemic_bounds.
  void stamp(CostmapGrid& grid, const SeenPerson& person, const CellWindow& clip) const;

 private:
  ProxemicLayerParams params_;
  std::vector<SeenPerson> people_;
  CellWindow last_bounds_;  // frame cells the last update's people covered
};

}  // namespace rfbsim::sim
