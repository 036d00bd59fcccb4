// SPDX-License-Identifier: GPL-2.0-or-later
// The costmap frame: a world-anchored grid covering the static map's bounding box plus a margin, in which
// the layers keep what must outlive one update (the static costs, the obstacle marks). A master grid (the
// whole map, or a rolling window) is a rectangle of the same cells, shifted by a whole number of cells.
#pragma once

#include <algorithm>
#include <cstdint>

#include "map/grid_map.hpp"
#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// Where a master grid sits in the frame: master cell (c, r) is frame cell (c + col, r + row).
struct FrameOffset {
  int col = 0;
  int row = 0;
};

/// The frame for `map`: the world-axis-aligned bounding box of the map's (possibly turned) grid, at
/// `resolution` m per cell, with `margin_cells` more on every side; all cells free.
CostmapGrid frame_for_map(const GridMap& map, double resolution, int margin_cells);

/// A frame window seen from the master grid (shifted by -offset), clipped to the master.
inline CellWindow frame_to_master(const CellWindow& frame_window, FrameOffset offset, const CostmapGrid& master) {
  return frame_window.shifted(-offset.col, -offset.row).clipped(master.width, master.height);
}

/// Walks the master cells of `window` row by row in runs: inside(master_cells, frame_cells, n) for a run
/// whose frame cells exist, outside(master_cells, n) for a run that lies beyond the frame.
template <class Inside, class Outside>
void for_each_run(CostmapGrid& master, const CellWindow& window, FrameOffset offset, const CostmapGrid& frame,
                  Inside&& inside, Outside&& outside) {
  if (window.empty()) return;
  // The window's columns split into at most three runs: left of the frame, in it, right of it.
  const int in_first = std::clamp(-offset.col, window.min_col, window.max_col + 1);
  const int in_end = std::clamp(frame.width - offset.col, in_first, window.max_col + 1);
  for (int row = window.min_row; row <= window.max_row; ++row) {
    std::uint8_t* master_row = &master.costs[master.index({0, row})];
    const int frame_row = row + offset.row;
    if (frame_row < 0 || frame_row >= frame.height) {
      outside(master_row + window.min_col, window.columns());
      continue;
    }
    if (in_first > window.min_col) outside(master_row + window.min_col, in_first - window.min_col);
    if (in_end > in_first) {
      const std::uint8_t* frame_cells = &frame.costs[frame.index({in_first + offset.col, frame_row})];
      inside(master_row + in_first, frame_cells, in_end - in_first);
    }
    if (window.max_col + 1 > in_end) outside(master_row + in_end, window.max_col + 1 - in_end);
  }
}

}  // namespace rfbsim::sim
