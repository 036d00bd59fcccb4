// SPDX-License-Identifier: GPL-2.0-or-later
// StaticLayer: the walls and props of the static map as lethal cells (costmap_2d's StaticLayer), sampled
// once onto the costmap frame.
#pragma once

#include "map/grid_map.hpp"
#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_frame.hpp"
#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

class StaticLayer {
 public:
  /// Marks lethal every cell of `frame` (geometry only) whose centre lies in a blocking cell of `map`
  /// (GridMap::is_occupied_at, so the map's own resolution, origin and yaw do not matter); the map's
  /// outside counts as blocking.
  StaticLayer(const GridMap& map, const CostmapGrid& frame);

  /// The frame's cells: cost::kLethal or cost::kFree.
  [[nodiscard]] const CostmapGrid& lethal() const { return lethal_; }
  /// Whether frame cell `c` is lethal; beyond the frame (outside the map) it is.
  [[nodiscard]] bool is_lethal(Cell c) const { return lethal_.at(c, cost::kLethal) == cost::kLethal; }

  /// Bounds: the whole frame on the first call (nothing is written yet), nothing after (the map is fixed).
  void update_bounds(CellWindow& frame_bounds);
  /// Writes the lethal cells into `window` of `master` (max with what is there); master cells beyond the
  /// frame are outside the map and so lethal.
  void update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset) const;

 private:
  CostmapGrid lethal_;
  bool written_ = false;
};

}  // namespace rfbsim::sim
