// SPDX-License-Identifier: GPL-2.0-or-later
// GridMap: an occupancy grid on the floor plane (row 0 at the bottom, +y up), as ROS maps are.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace rfbsim::sim {

/// Occupancy grid: cell (col, row) covers [origin_x + col*res, +res) x [origin_y + row*res, +res).
struct GridMap {
  int width = 0;            ///< columns
  int height = 0;           ///< rows
  double resolution = 0.5;  ///< m per cell
  double origin_x = 0.0;    ///< m, lower-left corner of cell (0, 0)
  double origin_y = 0.0;    ///< m
  std::vector<std::uint8_t> occupied;  ///< width * height, row-major from the bottom row; 1 = wall

  /// Whether (col, row) is a wall; outside the grid counts as wall, so nothing walks off the map.
  [[nodiscard]] bool is_occupied(int col, int row) const;
  /// The cell containing world point (x, y); may lie outside the grid.
  [[nodiscard]] int column_of(double x) const;
  [[nodiscard]] int row_of(double y) const;
  /// Whether a disc of `radius` at (x, y) overlaps any wall cell.
  [[nodiscard]] bool disc_hits_wall(double x, double y, double radius) const;
  /// How far a disc of `radius` can travel from (x, y) along the unit direction (dx, dy) before it
  /// touches a wall, up to `max_distance`, in steps of a tenth of a cell.
  [[nodiscard]] double free_distance(double x, double y, double dx, double dy, double max_distance,
                                     double radius) const;
};

/// A horizontal run of wall cells in one row: the unit walls are drawn with.
struct WallRun {
  int row = 0;
  int first_column = 0;
  int columns = 1;
};

/// Wall cells merged into horizontal runs (one box per run instead of one per cell).
std::vector<WallRun> merge_wall_runs(const GridMap& map);

/// Builds a map from rows of text, top row first: '#' is wall, anything else is free.
/// Throws std::invalid_argument if rows differ in length or there are none.
GridMap grid_from_text(std::initializer_list<std::string_view> rows_top_first, double resolution);

/// The small built-in room sim_rfb starts in until scenarios exist: 12 m x 9 m with an inner wall.
GridMap builtin_test_room();

}  // namespace rfbsim::sim
