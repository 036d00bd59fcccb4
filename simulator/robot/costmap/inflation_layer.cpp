// SPDX-License-Identifier: GPL-2.0-or-later
// InflationLayer: the kernel, stamping, the cached static inflation and the per-update pass.
#include "robot/costmap/inflation_layer.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::sim {

namespace {
constexpr double kSlack = 1e-9;  // m: cell distances are products of the resolution; forgive their rounding
}  // namespace

std::uint8_t inflation_cost(double distance, double inscribed_radius, const InflationLayerParams& params) {
  if (distance <= kSlack) return cost::kLethal;
  // Beyond the radius nothing, even inside the inscribed radius (nav2 never visits those cells).
  if (distance > params.inflation_radius + kSlack) return cost::kFree;
  if (distance <= inscribed_radius + kSlack) return cost::kInscribed;
  const double value = (cost::kInscribed - 1) * std::exp(-params.cost_scaling_factor * (distance - inscribed_radius));
  return static_cast<std::uint8_t>(std::floor(value));
}

InflationLayer::InflationLayer(const InflationLayerParams& params, double inscribed_radius, double resolution)
    : radius_(static_cast<int>(std::ceil(params.inflation_radius / resolution - kSlack))) {
  radius_ = std::max(radius_, 0);
  const int side = 2 * radius_ + 1;
  kernel_.resize(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
  for (int drow = -radius_; drow <= radius_; ++drow) {
    for (int dcol = -radius_; dcol <= radius_; ++dcol) {
      const double d = resolution * std::sqrt(static_cast<double>(dcol * dcol + drow * drow));
      kernel_[static_cast<std::size_t>((drow + radius_) * side + dcol + radius_)] =
          inflation_cost(d, inscribed_radius, params);
    }
  }
}

std::uint8_t InflationLayer::kernel_at(int dcol, int drow) const {
  if (std::abs(dcol) > radius_ || std::abs(drow) > radius_) return cost::kFree;
  return kernel_[static_cast<std::size_t>((drow + radius_) * (2 * radius_ + 1) + dcol + radius_)];
}

void InflationLayer::stamp(CostmapGrid& grid, Cell centre, const CellWindow& clip) const {
  const CellWindow reach{centre.col - radius_, centre.row - radius_, centre.col + radius_, centre.row + radius_};
  const CellWindow w = reach.intersected(clip).clipped(grid.width, grid.height);
  if (w.empty()) return;
  const int side = 2 * radius_ + 1;
  const int n = w.columns();
  for (int row = w.min_row; row <= w.max_row; ++row) {
    const std::uint8_t* k =
        &kernel_[static_cast<std::size_t>((row - centre.row + radius_) * side + w.min_col - centre.col + radius_)];
    std::uint8_t* out = &grid.costs[grid.index({w.min_col, row})];
    for (int i = 0; i < n; ++i) out[i] = std::max(out[i], k[i]);
  }
}

void InflationLayer::inflate(CostmapGrid& grid) const {
  // Only lethal cells with a non-lethal neighbour (4-connected, inside the grid) need a stamp: every
  // non-lethal cell's nearest lethal cell is one of them, since a lethal neighbour on the way would be
  // nearer. Stamps never write 254 off their centre, so reading "lethal" while stamping stays exact.
  const CellWindow all = CellWindow::whole(grid.width, grid.height);
  const auto lethal = [&grid](int col, int row) {
    return !grid.in_bounds({col, row}) || grid.costs[grid.index({col, row})] == cost::kLethal;
  };
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      if (grid.costs[grid.index({col, row})] != cost::kLethal) continue;
      const bool edge = (col > 0 && !lethal(col - 1, row)) || (col + 1 < grid.width && !lethal(col + 1, row)) ||
                        (row > 0 && !lethal(col, row - 1)) || (row + 1 < grid.height && !lethal(col, row + 1));
      if (edge) stamp(grid, {col, row}, all);
    }
  }
}

void InflationLayer::cache_static(const StaticLayer& statics) {
  static_cache_ = statics.lethal();
  inflate(static_cache_);
}

void InflationLayer::update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset,
                                  const StaticLayer* statics, const ObstacleLayer* obstacles) const {
  if (window.empty()) return;
  if (statics != nullptr && !static_cache_.costs.empty()) {
    for_each_run(
        master, window, offset, static_cache_,
        [](std::uint8_t* out, const std::uint8_t* in, int n) {
          for (int i = 0; i < n; ++i) out[i] = std::max(out[i], in[i]);
        },
        [](std::uint8_t* out, int n) { std::fill(out, out + n, cost::kLethal); });
  }
  if (obstacles == nullptr) return;
  // Marks up to radius_ cells outside the window still reach into it.
  obstacles->for_each_mark(window.shifted(offset.col, offset.row).grown(radius_), [&](Cell c) {
    if (statics != nullptr && statics->is_lethal(c)) return;  // its inflation is in the cache already
    stamp(master, {c.col - offset.col, c.row - offset.row}, window);
  });
}

}  // namespace rfbsim::sim
