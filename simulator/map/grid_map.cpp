// SPDX-License-Identifier: GPL-2.0-or-later
// GridMap queries, wall merging and the built-in test room.
#include "map/grid_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rfbsim::sim {

bool GridMap::is_occupied(int col, int row) const {
  if (col < 0 || row < 0 || col >= width || row >= height) return true;
  return occupied[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)] != 0;
}

bool GridMap::is_occupied_at(double x, double y) const { return is_occupied(cell_of(x, y)); }

Eigen::Vector2d GridMap::to_map_frame(double x, double y) const {
  const double dx = x - origin_x;
  const double dy = y - origin_y;
  if (origin_yaw == 0.0) return {dx, dy};
  const double c = std::cos(origin_yaw);
  const double s = std::sin(origin_yaw);
  return {c * dx + s * dy, -s * dx + c * dy};
}

Eigen::Vector2d GridMap::to_world(Eigen::Vector2d p) const {
  if (origin_yaw == 0.0) return {origin_x + p.x(), origin_y + p.y()};
  const double c = std::cos(origin_yaw);
  const double s = std::sin(origin_yaw);
  return {origin_x + c * p.x() - s * p.y(), origin_y + s * p.x() + c * p.y()};
}

Cell GridMap::cell_of(double x, double y) const {
  const Eigen::Vector2d p = to_map_frame(x, y);
  return {static_cast<int>(std::floor(p.x() / resolution)), static_cast<int>(std::floor(p.y() / resolution))};
}

Eigen::Vector2d GridMap::cell_centre(Cell c) const {
  return to_world({(c.col + 0.5) * resolution, (c.row + 0.5) * resolution});
}

bool GridMap::contains(double x, double y) const {
  const Cell c = cell_of(x, y);
  return c.col >= 0 && c.row >= 0 && c.col < width && c.row < height;
}

bool GridMap::disc_hits_wall(double x, double y, double radius) const {
  // In the map frame, test every cell the disc's bounding square touches by the cell's closest point.
  const Eigen::Vector2d p = to_map_frame(x, y);
  const auto index = [this](double v) { return static_cast<int>(std::floor(v / resolution)); };
  for (int row = index(p.y() - radius); row <= index(p.y() + radius); ++row) {
    for (int col = index(p.x() - radius); col <= index(p.x() + radius); ++col) {
      if (!is_occupied(col, row)) continue;
      const double x0 = col * resolution;
      const double y0 = row * resolution;
      const double cx = std::clamp(p.x(), x0, x0 + resolution);
      const double cy = std::clamp(p.y(), y0, y0 + resolution);
      if ((cx - p.x()) * (cx - p.x()) + (cy - p.y()) * (cy - p.y()) < radius * radius) return true;
    }
  }
  return false;
}

double GridMap::free_distance(double x, double y, double dx, double dy, double max_distance, double radius) const {
  const double step = resolution / 10.0;
  double travelled = 0.0;
  while (travelled < max_distance) {
    const double next = std::min(travelled + step, max_distance);
    if (disc_hits_wall(x + dx * next, y + dy * next, radius)) return travelled;
    travelled = next;
  }
  return max_distance;
}

double GridMap::ray_cast(double x, double y, double angle, double max_range) const {
  // Amanatides-Woo traversal in the map frame, in units of cells.
  const Eigen::Vector2d p = to_map_frame(x, y) / resolution;
  const double dir_x = std::cos(angle - origin_yaw);
  const double dir_y = std::sin(angle - origin_yaw);
  int col = static_cast<int>(std::floor(p.x()));
  int row = static_cast<int>(std::floor(p.y()));
  if (is_occupied(col, row)) return 0.0;
  const double max_cells = max_range / resolution;
  const int step_col = dir_x > 0 ? 1 : -1;
  const int step_row = dir_y > 0 ? 1 : -1;
  constexpr double kNever = std::numeric_limits<double>::infinity();
  const double delta_col = dir_x != 0.0 ? std::abs(1.0 / dir_x) : kNever;
  const double delta_row = dir_y != 0.0 ? std::abs(1.0 / dir_y) : kNever;
  double next_col = dir_x > 0 ? (col + 1 - p.x()) * delta_col : dir_x < 0 ? (p.x() - col) * delta_col : kNever;
  double next_row = dir_y > 0 ? (row + 1 - p.y()) * delta_row : dir_y < 0 ? (p.y() - row) * delta_row : kNever;
  for (;;) {
    double travelled = 0.0;
    if (next_col < next_row) {
      travelled = next_col;
      next_col += delta_col;
      col += step_col;
    } else {
      travelled = next_row;
      next_row += delta_row;
      row += step_row;
    }
    if (travelled >= max_cells) return max_range;
    // Leaving the grid ends the ray there: outside counts as wall.
    if (is_occupied(col, row)) return travelled * resolution;
  }
}

void GridMap::block_box(double cx, double cy, double size_x, double size_y, double yaw) {
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  const double reach = 0.5 * std::hypot(size_x, size_y);
  const Eigen::Vector2d low = to_map_frame(cx, cy).array() - reach;
  const Eigen::Vector2d high = to_map_frame(cx, cy).array() + reach;
  for (int row = std::max(0, static_cast<int>(std::floor(low.y() / resolution)));
       row <= std::min(height - 1, static_cast<int>(std::floor(high.y() / resolution))); ++row) {
    for (int col = std::max(0, static_cast<int>(std::floor(low.x() / resolution)));
         col <= std::min(width - 1, static_cast<int>(std::floor(high.x() / resolution))); ++col) {
      const Eigen::Vector2d centre = cell_centre({col, row});
      const double dx = centre.x() - cx;
      const double dy = centre.y() - cy;
      const double along = c * dx + s * dy;
      const double across = -s * dx + c * dy;
      if (std::abs(along) <= size_x / 2 && std::abs(across) <= size_y / 2) {
        occupied[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)] = 1;
      }
    }
  }
}

std::vector<WallRect> merge_wall_rectangles(const GridMap& map) {
  // Greedy: take the lowest-leftmost unclaimed blocking cell, extend right along the row, then upward
  // while the whole span above is blocking and unclaimed.
  std::vector<std::uint8_t> claimed(map.occupied.size(), 0);
  const auto index = [&map](int col, int row) {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(col);
  };
  const auto free_to_claim = [&](int col, int row) { return map.is_occupied(col, row) && !claimed[index(col, row)]; };
  std::vector<WallRect> rects;
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      if (!free_to_claim(col, row)) continue;
      WallRect rect{col, row, 0, 1};
      while (col + rect.columns < map.width && free_to_claim(col + rect.columns, row)) ++rect.columns;
      for (;;) {
        const int above = row + rect.rows;
        if (above >= map.height) break;
        bool whole = true;
        for (int c = col; c < col + rect.columns && whole; ++c) whole = free_to_claim(c, above);
        if (!whole) break;
        ++rect.rows;
      }
      for (int r = row; r < row + rect.rows; ++r) {
        for (int c = col; c < col + rect.columns; ++c) claimed[index(c, r)] = 1;
      }
      rects.push_back(rect);
      col += rect.columns - 1;
    }
  }
  return rects;
}

GridMap grid_from_text(std::initializer_list<std::string_view> rows_top_first, double resolution) {
  if (rows_top_first.size() == 0) throw std::invalid_argument("grid_from_text: no rows");
  GridMap map;
  map.height = static_cast<int>(rows_top_first.size());
  map.width = static_cast<int>(rows_top_first.begin()->size());
  map.resolution = resolution;
  map.occupied.assign(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height), 0);
  int text_row = 0;
  for (const std::string_view line : rows_top_first) {
    if (static_cast<int>(line.size()) != map.width) {
      throw std::invalid_argument("grid_from_text: row " + std::to_string(text_row) + " has " +
                                  std::to_string(line.size()) + " cells, expected " + std::to_string(map.width));
    }
    // The text's top row is the grid's highest row (+y up), as in ROS map images.
    const int row = map.height - 1 - text_row;
    for (int col = 0; col < map.width; ++col) {
      map.occupied[static_cast<std::size_t>(row * map.width + col)] = line[static_cast<std::size_t>(col)] == '#' ? 1 : 0;
    }
    ++text_row;
  }
  return map;
}

GridMap walled_grid(double width, double height, double res, const std::vector<WallBlock>& blocks) {
  GridMap map;
  map.width = static_cast<int>(std::lround(width / res));
  map.height = static_cast<int>(std::lround(height / res));
  map.resolution = res;
  map.occupied.assign(static_cast<std::size_t>(map.width * map.height), 0);
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      bool wall = row == 0 || col == 0 || row == map.height - 1 || col == map.width - 1;
      const double x = (col + 0.5) * res;
      const double y = (row + 0.5) * res;
      for (const WallBlock& b : blocks) wall = wall || (x > b.x && x < b.x + b.w && y > b.y && y < b.y + b.h);
      map.occupied[static_cast<std::size_t>(row * map.width + col)] = wall ? 1 : 0;
    }
  }
  return map;
}

GridMap builtin_test_room() {
  // 24 x 18 cells of 0.5 m, centred on the origin: an outer wall, an inner wall with a doorway, a pillar.
  GridMap map = grid_from_text(
      {
          "########################",
          "#......................#",
          "#......................#",
          "#......................#",
          "#..............##......#",
          "#..............##......#",
          "#......................#",
          "#......................#",
          "#######.######.........#",
          "#......................#",
          "#......................#",
          "#......................#",
          "#......................#",
          "#......................#",
          "#......................#",
          "#......................#",
          "#......................#",
          "########################",
      },
      0.5);
  map.origin_x = -6.0;
  map.origin_y = -4.5;
  return map;
}

}  // namespace rfbsim::sim
