// SPDX-License-Identifier: GPL-2.0-or-later
// GridMap: an occupancy grid on the floor plane, laid out as ROS maps are: row 0 at the bottom, +y up,
// the lower-left corner of cell (0, 0) at the origin, the grid's axes turned by origin_yaw.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <string_view>
#include <vector>

namespace rfbsim::sim {

/// A cell index; may lie outside the grid.
struct Cell {
  int col = 0;
  int row = 0;
  bool operator==(const Cell&) const = default;
};

/// Occupancy grid: in the map frame, cell (col, row) covers [col*res, +res) x [row*res, +res); the map
/// frame is placed in the world at (origin_x, origin_y), turned by origin_yaw.
struct GridMap {
  int width = 0;            ///< columns
  int height = 0;           ///< rows
  double resolution = 0.5;  ///< m per cell
  double origin_x = 0.0;    ///< m, world position of the lower-left corner of cell (0, 0)
  double origin_y = 0.0;    ///< m
  double origin_yaw = 0.0;  ///< rad, the grid's +col axis against the world's +x
  /// width * height, row-major from the bottom row; 1 = blocks (occupied, or unknown space), 0 = free.
  std::vector<std::uint8_t> occupied;

  /// Whether (col, row) blocks; outside the grid counts as blocking, so nothing walks off the map.
  [[nodiscard]] bool is_occupied(int col, int row) const;
  [[nodiscard]] bool is_occupied(Cell c) const { return is_occupied(c.col, c.row); }
  /// Whether the world point (x, y) lies in a blocking cell.
  [[nodiscard]] bool is_occupied_at(double x, double y) const;
  /// World point -> map frame (metres from the origin along the grid's axes) and back.
  [[nodiscard]] Eigen::Vector2d to_map_frame(double x, double y) const;
  [[nodiscard]] Eigen::Vector2d to_world(Eigen::Vector2d map_point) const;
  /// The cell containing world point (x, y).
  [[nodiscard]] Cell cell_of(double x, double y) const;
  /// World position of a cell's centre.
  [[nodiscard]] Eigen::Vector2d cell_centre(Cell c) const;
  /// Whether the world point lies on the grid at all.
  [[nodiscard]] bool contains(double x, double y) const;
  /// Whether a disc of `radius` at (x, y) overlaps any blocking cell.
  [[nodiscard]] bool disc_hits_wall(double x, double y, double radius) const;
  /// How far a disc of `radius` can travel from (x, y) along the unit direction (dx, dy) before it
  /// touches a wall, up to `max_distance`, in steps of a tenth of a cell.
  [[nodiscard]] double free_distance(double x, double y, double dx, double dy, double max_distance,
                                     double radius) const;
  /// Distance from (x, y) along the world angle `angle` to the first blocking cell's edge (an exact grid
  /// traversal), or `max_range` if none is nearer. 0 when (x, y) is inside a blocking cell.
  [[nodiscard]] double ray_cast(double x, double y, double angle, double max_range) const;
  /// Marks every cell whose centre lies inside the world box (centre, full sizes, yaw) as blocking.
  void block_box(double cx, double cy, double size_x, double size_y, double yaw);
};

/// A rectangle of blocking cells: the unit walls are built from (in grid cells).
struct WallRect {
  int first_column = 0;
  int first_row = 0;
  int columns = 1;
  int rows = 1;
};

/// Blocking cells merged greedily into rectangles: runs along rows, then equal runs stacked upward.
/// Every blocking cell is in exactly one rectangle; a typical map needs a few dozen.
std::vector<WallRect> merge_wall_rectangles(const GridMap& map);

/// Builds a map from rows of text, top row first: '#' is wall, anything else is free.
/// Throws std::invalid_argument if rows differ in length or there are none.
GridMap grid_from_text(std::initializer_list<std::string_view> rows_top_first, double resolution);

/// A block of wall in walled_grid, world metres (lower-left corner and size).
struct WallBlock {
  double x = 0.0;
  double y = 0.0;
  double w = 0.0;
  double h = 0.0;
};

/// A `width` x `height` m grid of `res` m cells with its origin at (0, 0), a one-cell wall all round, and
/// every cell whose centre lies strictly inside one of `blocks` blocked (tests and small examples).
GridMap walled_grid(double width, double height, double res, const std::vector<WallBlock>& blocks = {});

/// The small built-in room: 12 m x 9 m with an inner wall (tests and the demo without a scenario).
GridMap builtin_test_room();

}  // namespace rfbsim::sim
