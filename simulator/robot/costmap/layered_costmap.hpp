// SPDX-License-Identifier: GPL-2.0-or-later
// LayeredCostmap: one costmap_2d-style costmap (global over the static map, or a rolling window on the
// robot) built from its layers in order: static, obstacle, inflation, proxemic. Each update first lets every
// layer grow a dirty window (nav2's updateBounds), then rewrites only that window (updateCosts), each
// layer taking the max with what the layers before it wrote.
//
// Ownership: the costmap copies what it needs from the static map at construction; update() reads the scan
// and the people only during the call. grid() and social() stay valid until the costmap is destroyed.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "map/grid_map.hpp"
#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_frame.hpp"
#include "robot/costmap/costmap_grid.hpp"
#include "robot/costmap/costmap_params.hpp"
#include "robot/costmap/inflation_layer.hpp"
#include "robot/costmap/obstacle_layer.hpp"
#include "robot/costmap/proxemic_layer.hpp"
#include "robot/costmap/seen_person.hpp"
#include "robot/costmap/static_layer.hpp"
#include "robot/sensing/laser_scan.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What one update did, for logs and debugging.
struct CostmapUpdateReport {
  bool scan_used = false;              ///< the scan was raytraced and marked
  const char* scan_skipped = nullptr;  ///< why not (e.g. "no scan", "robot pose is not finite"); null if used
  int people_used = 0;                 ///< people with a finite position that went into the proxemic layer
  CellWindow window;                   ///< the master cells rewritten (the dirty window), in grid() indices
};

class LayeredCostmap {
 public:
  /// Samples `static_map` onto the costmap's cells and caches its inflation. The global costmap covers the
  /// map's bounding box; a rolling one is params.width x params.height m, centred on the frame until the
  /// first update with a valid pose. Throws std::invalid_argument for out-of-range parameters (validate()).
  LayeredCostmap(const GridMap& static_map, CostmapParams params = {});

  /// One update from the robot's estimated pose (m, rad), this cycle's scan (null: none) and the people the
  /// caller decided the robot sees. A rolling window re-centres on the pose first. The robot's footprint is
  /// cleared of obstacle marks. A non-finite pose skips the scan and keeps the window where it was.
  CostmapUpdateReport update(const Pose2& robot_pose, const LaserScan* scan, std::span<const SeenPerson> people);

  /// The master costs (max over the layers); cost::kFree .. cost::kLethal.
  [[nodiscard]] const CostmapGrid& grid() const { return master_; }
  /// The proxemic layer's own costs, on grid()'s cells (0 where no one is), for the debug overlay.
  [[nodiscard]] const CostmapGrid& social() const { return social_; }
  /// The parameters it was built with.
  [[nodiscard]] const CostmapParams& params() const { return params_; }

  /// Drops every obstacle mark farther than `distance` m from `centre` (the "clear costmap" recovery) and
  /// rewrites the affected cells at once; returns how many marks went. 0 when the obstacle layer is off.
  int clear_obstacles_beyond(const Eigen::Vector2d& centre, double distance);
  /// Drops every obstacle mark and rewrites the affected cells at once.
  void clear_obstacles();

  /// The obstacle layer (null when off): its world-anchored marks, for tests and debugging.
  [[nodiscard]] const ObstacleLayer* obstacle_layer() const { return obstacle_ ? &*obstacle_ : nullptr; }
  /// The frame's geometry (its costs are empty): the world-anchored cells the layers keep their state in.
  [[nodiscard]] const CostmapGrid& frame() const { return frame_; }

 private:
  /// Moves a rolling window so that the robot's cell is its middle one.
  void recentre(double x, double y);
  /// The costs phase over master cells `window`: zero, then every layer in order.
  void write_costs(const CellWindow& window);
  /// Rewrites what the obstacle layer changed since the last update (after a clear).
  void refresh_obstacles();

  CostmapParams params_;
  CostmapGrid frame_;
  std::optional<StaticLayer> static_;
  std::optional<ObstacleLayer> obstacle_;
  std::optional<InflationLayer> inflation_;
  std::optional<ProxemicLayer> proxemic_;
  CostmapGrid master_;
  CostmapGrid social_;
  FrameOffset offset_;  // where master_ sits in frame_
  bool written_ = false;
};

}  // namespace rfbsim::sim
