// SPDX-License-Identifier: GPL-2.0-or-later
// Small costmaps for the planner tests: grids from text, hand-made inflation, a brute-force Dijkstra to check
// the global planner against, and a rolling window cut from a larger costmap.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim::test {

/// A costmap from rows of text, top row first, origin (0, 0): '.' free, '#' lethal, 'i' inscribed,
/// '?' unknown, a digit k cost 25 k.
inline CostmapGrid costmap_from_text(std::initializer_list<std::string_view> rows_top_first, double resolution) {
  const auto height = static_cast<int>(rows_top_first.size());
  if (height == 0) throw std::invalid_argument("no rows");
  const auto width = static_cast<int>(rows_top_first.begin()->size());
  CostmapGrid grid = CostmapGrid::sized(width, height, resolution, 0.0, 0.0);
  int row = height - 1;
  for (const std::string_view text : rows_top_first) {
    if (static_cast<int>(text.size()) != width) throw std::invalid_argument("ragged rows");
    for (int col = 0; col < width; ++col) {
      const char ch = text[static_cast<std::size_t>(col)];
      std::uint8_t value = cost::kFree;
      if (ch == '#') value = cost::kLethal;
      if (ch == 'i') value = cost::kInscribed;
      if (ch == '?') value = cost::kUnknown;
      if (ch >= '1' && ch <= '9') value = static_cast<std::uint8_t>(25 * (ch - '0'));
      grid.set({col, row}, value);
    }
    --row;
  }
  return grid;
}

/// Inflates the lethal cells of `grid` as costmap_2d does: 253 within `inscribed` m of a lethal cell's
/// centre, floor(252 exp(-k (d - inscribed))) up to `inflation` m (brute force, for small grids).
inline void inflate(CostmapGrid& grid, double inscribed, double inflation, double k = 3.0) {
  const std::vector<std::uint8_t> source = grid.costs;
  const int reach = static_cast<int>(std::ceil(inflation / grid.resolution));
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      if (source[grid.index({col, row})] != cost::kLethal) continue;
      for (int dr = -reach; dr <= reach; ++dr) {
        for (int dc = -reach; dc <= reach; ++dc) {
          const Cell c{col + dc, row + dr};
          if (!grid.in_bounds(c) || source[grid.index(c)] == cost::kLethal) continue;
          const double d = std::hypot(dc, dr) * grid.resolution;
          if (d > inflation) continue;
          const auto value = d <= inscribed ? cost::kInscribed
                                            : static_cast<std::uint8_t>(std::floor(252.0 * std::exp(-k * (d - inscribed))));
          std::uint8_t& cell = grid.costs[grid.index(c)];
          cell = std::max(cell, value);
        }
      }
    }
  }
}

/// The cheapest cost from `start` to `goal` by plain O(n^2) Dijkstra with the planner's rules written out
/// independently: 8 neighbours, a cell of cost c < lethal costs min(50 + 3c, 252) per cell length to enter
/// (sqrt 2 times that diagonally), no diagonal step unless both cells beside it are passable. +inf if none.
inline double brute_force_cost(const CostmapGrid& grid, Cell start, Cell goal) {
  const std::size_t n = grid.costs.size();
  const auto enter = [&](Cell c) {
    if (!grid.in_bounds(c)) return std::numeric_limits<double>::infinity();
    const int value = grid.at(c);
    return value >= 253 ? std::numeric_limits<double>::infinity() : std::min(50.0 + 3.0 * value, 252.0);
  };
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<bool> done(n, false);
  dist[grid.index(start)] = 0.0;
  for (;;) {
    std::size_t at = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (!done[i] && std::isfinite(dist[i]) && (at == n || dist[i] < dist[at])) at = i;
    }
    if (at == n) break;
    done[at] = true;
    const Cell c{static_cast<int>(at % static_cast<std::size_t>(grid.width)),
                 static_cast<int>(at / static_cast<std::size_t>(grid.width))};
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        const Cell next{c.col + dc, c.row + dr};
        double step = enter(next);
        if (dr != 0 && dc != 0) {
          if (!std::isfinite(enter({c.col + dc, c.row})) || !std::isfinite(enter({c.col, c.row + dr}))) continue;
          step *= std::sqrt(2.0);
        }
        if (!std::isfinite(step)) continue;
        double& d = dist[grid.index(next)];
        d = std::min(d, dist[at] + step);
      }
    }
  }
  return dist[grid.index(goal)];
}

/// A `size` x `size` m window of `grid` centred on the cell holding (x, y), snapped to its cells (what a
/// rolling local costmap holds); cells beyond `grid` read unknown.
inline CostmapGrid window_of(const CostmapGrid& grid, double x, double y, double size) {
  const int cells = static_cast<int>(std::lround(size / grid.resolution));
  const Cell centre = grid.cell_of(x, y);
  const Cell corner{centre.col - cells / 2, centre.row - cells / 2};
  CostmapGrid window = CostmapGrid::sized(cells, cells, grid.resolution, grid.origin_x + corner.col * grid.resolution,
                                          grid.origin_y + corner.row * grid.resolution);
  for (int row = 0; row < cells; ++row) {
    for (int col = 0; col < cells; ++col) window.set({col, row}, grid.at({corner.col + col, corner.row + row}, cost::kUnknown));
  }
  return window;
}

/// Every point of `path` lies in a cell cheaper than `limit`.
inline bool path_below(const CostmapGrid& grid, const std::vector<Eigen::Vector2d>& path, int limit) {
  return std::all_of(path.begin(), path.end(),
                     [&](const Eigen::Vector2d& p) { return grid.at_world(p.x(), p.y()) < limit; });
}

}  // namespace rfbsim::sim::test
