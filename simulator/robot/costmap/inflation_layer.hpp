// SPDX-License-Identifier: GPL-2.0-or-later
// InflationLayer: costs that fall off with the distance to the nearest lethal cell (costmap_2d's
// InflationLayer), by stamping a precomputed kernel of costs per cell offset. The static map's inflation is
// computed once and cached; each update stamps only the obstacle marks near the dirty window.
#pragma once

#include <cstdint>
#include <vector>

#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_frame.hpp"
#include "robot/costmap/costmap_grid.hpp"
#include "robot/costmap/costmap_params.hpp"
#include "robot/costmap/obstacle_layer.hpp"
#include "robot/costmap/static_layer.hpp"

namespace rfbsim::sim {

/// The cost of a cell `distance` m (between cell centres) from the nearest lethal cell (docs/sources.md):
/// 254 at 0; 0 beyond inflation_radius; else 253 up to `inscribed_radius` and
/// floor(252 exp(-cost_scaling_factor (d - inscribed_radius))) past it. The comparisons allow 1e-9 m, so
/// that 6 cells of 0.05 m count as 0.3 m.
std::uint8_t inflation_cost(double distance, double inscribed_radius, const InflationLayerParams& params);

class InflationLayer {
 public:
  /// Precomputes the kernel for a grid of `resolution` m per cell.
  InflationLayer(const InflationLayerParams& params, double inscribed_radius, double resolution);

  /// How many cells the inflation reaches from a lethal cell (its kernel's half-width).
  [[nodiscard]] int radius_cells() const { return radius_; }
  /// The kernel: the cost `dcol`, `drow` cells away from a lethal cell (0 beyond the radius).
  [[nodiscard]] std::uint8_t kernel_at(int dcol, int drow) const;

  /// Inflates every lethal cell of `grid` in place, each cell taking the max with what it holds.
  void inflate(CostmapGrid& grid) const;
  /// Stamps the kernel centred on `centre` into `grid` (max with what is there), only inside `clip`.
  void stamp(CostmapGrid& grid, Cell centre, const CellWindow& clip) const;
  /// Computes and keeps the inflation of the static layer's lethal cells, on the frame's cells.
  void cache_static(const StaticLayer& statics);
  /// The cached static inflation (empty before cache_static).
  [[nodiscard]] const CostmapGrid& static_inflation() const { return static_cache_; }

  /// Bounds: anything that changed reaches radius_cells() farther.
  void update_bounds(CellWindow& frame_bounds) const { frame_bounds = frame_bounds.grown(radius_); }
  /// Writes into `window` of `master` (max with what is there): the cached static inflation when `statics`
  /// is given (beyond the frame: lethal), then the kernel of every obstacle mark within reach of the
  /// window that is not already static-lethal. Since the cost falls with distance, the max over the
  /// stamps is the cost of the nearest lethal cell. Either pointer may be null (that layer is off).
  void update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset, const StaticLayer* statics,
                    const ObstacleLayer* obstacles) const;

 private:
  int radius_ = 0;
  std::vector<std::uint8_t> kernel_;  // (2 radius + 1)^2, row-major from drow = -radius
  CostmapGrid static_cache_;
};

}  // namespace rfbsim::sim
