// SPDX-License-Identifier: GPL-2.0-or-later
// StaticLayer: sampling the map once, copying it into the master's dirty window.
#include "robot/costmap/static_layer.hpp"

#include <algorithm>

namespace rfbsim::sim {

StaticLayer::StaticLayer(const GridMap& map, const CostmapGrid& frame)
    : lethal_(CostmapGrid::sized(frame.width, frame.height, frame.resolution, frame.origin_x, frame.origin_y)) {
  for (int row = 0; row < lethal_.height; ++row) {
    for (int col = 0; col < lethal_.width; ++col) {
      const Eigen::Vector2d centre = lethal_.cell_centre({col, row});
      if (map.is_occupied_at(centre.x(), centre.y())) lethal_.costs[lethal_.index({col, row})] = cost::kLethal;
    }
  }
}

void StaticLayer::update_bounds(CellWindow& frame_bounds) {
  if (written_) return;
  frame_bounds.include(CellWindow::whole(lethal_.width, lethal_.height));
  written_ = true;
}

void StaticLayer::update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset) const {
  for_each_run(
      master, window, offset, lethal_,
      [](std::uint8_t* out, const std::uint8_t* in, int n) {
        for (int i = 0; i < n; ++i) out[i] = std::max(out[i], in[i]);
      },
      [](std::uint8_t* out, int n) { std::fill(out, out + n, cost::kLethal); });
}

}  // namespace rfbsim::sim
