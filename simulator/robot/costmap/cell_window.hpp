// SPDX-License-Identifier: GPL-2.0-or-later
// CellWindow: an inclusive rectangle of cells, the "dirty window" costmap layers grow before they write
// (nav2's updateBounds), kept in whatever grid's cell indices the owner says.
#pragma once

#include <algorithm>
#include <climits>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

/// Cells [min_col, max_col] x [min_row, max_row], both ends included; empty when min > max.
struct CellWindow {
  int min_col = INT_MAX;
  int min_row = INT_MAX;
  int max_col = INT_MIN;
  int max_row = INT_MIN;

  /// The window that holds nothing (the start of a union).
  static CellWindow none() { return {}; }
  /// All cells of a width x height grid.
  static CellWindow whole(int width, int height) { return {0, 0, width - 1, height - 1}; }

  /// Whether the window holds no cell.
  [[nodiscard]] bool empty() const { return min_col > max_col || min_row > max_row; }
  /// Its width and height in cells (0 when empty).
  [[nodiscard]] int columns() const { return empty() ? 0 : max_col - min_col + 1; }
  [[nodiscard]] int rows() const { return empty() ? 0 : max_row - min_row + 1; }
  /// Whether cell `c` lies in the window.
  [[nodiscard]] bool contains(Cell c) const {
    return c.col >= min_col && c.col <= max_col && c.row >= min_row && c.row <= max_row;
  }

  /// Grows the window to hold cell `c`.
  void include(Cell c) {
    min_col = std::min(min_col, c.col);
    min_row = std::min(min_row, c.row);
    max_col = std::max(max_col, c.col);
    max_row = std::max(max_row, c.row);
  }
  /// Grows the window to hold all of `other` (nothing when `other` is empty).
  void include(const CellWindow& other) {
    if (other.empty()) return;
    include(Cell{other.min_col, other.min_row});
    include(Cell{other.max_col, other.max_row});
  }
  /// This window with `cells` more on every side (unchanged when empty).
  [[nodiscard]] CellWindow grown(int cells) const {
    if (empty()) return *this;
    return {min_col - cells, min_row - cells, max_col + cells, max_row + cells};
  }
  /// The cells in both windows (possibly none).
  [[nodiscard]] CellWindow intersected(const CellWindow& other) const {
    return {std::max(min_col, other.min_col), std::max(min_row, other.min_row), std::min(max_col, other.max_col),
            std::min(max_row, other.max_row)};
  }
  /// The part of this window inside a width x height grid (possibly empty).
  [[nodiscard]] CellWindow clipped(int width, int height) const { return intersected(whole(width, height)); }
  /// The same cells seen from a grid whose cell (0, 0) is this grid's (col, row) = (-dcol, -drow), i.e.
  /// every index plus (dcol, drow).
  [[nodiscard]] CellWindow shifted(int dcol, int drow) const {
    if (empty()) return *this;
    return {min_col + dcol, min_row + drow, max_col + dcol, max_row + drow};
  }
};

}  // namespace rfbsim::sim
