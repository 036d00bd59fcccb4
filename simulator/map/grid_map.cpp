// SPDX-License-Identifier: GPL-2.0-or-later
// GridMap queries, wall merging and the built-in test room.
#include "map/grid_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rfbsim::sim {

bool GridMap::is_occupied(int col, int row) const {
  if (col < 0 || row < 0 || col >= width || row >= height) return true;
  return occupied[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)] != 0;
}

int GridMap::column_of(double x) const { return static_cast<int>(std::floor((x - origin_x) / resolution)); }
int GridMap::row_of(double y) const { return static_cast<int>(std::floor((y - origin_y) / resolution)); }

bool GridMap::disc_hits_wall(double x, double y, double radius) const {
  // Test every cell the disc's bounding square touches, by the closest point of the cell to the centre.
  for (int row = row_of(y - radius); row <= row_of(y + radius); ++row) {
    for (int col = column_of(x - radius); col <= column_of(x + radius); ++col) {
      if (!is_occupied(col, row)) continue;
      const double x0 = origin_x + col * resolution;
      const double y0 = origin_y + row * resolution;
      const double cx = std::clamp(x, x0, x0 + resolution);
      const double cy = std::clamp(y, y0, y0 + resolution);
      if ((cx - x) * (cx - x) + (cy - y) * (cy - y) < radius * radius) return true;
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

std::vector<WallRun> merge_wall_runs(const GridMap& map) {
  std::vector<WallRun> runs;
  for (int row = 0; row < map.height; ++row) {
    int col = 0;
    while (col < map.width) {
      if (!map.is_occupied(col, row)) {
        ++col;
        continue;
      }
      WallRun run{row, col, 0};
      while (col < map.width && map.is_occupied(col, row)) {
        ++run.columns;
        ++col;
      }
      runs.push_back(run);
    }
  }
  return runs;
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
