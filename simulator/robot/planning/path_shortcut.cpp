// SPDX-License-Identifier: GPL-2.0-or-later
// Path shortcuts: an exact walk of the cells a segment crosses, and a greedy search for the farthest
// acceptable segment from each kept cell.
#include "robot/planning/path_shortcut.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace rfbsim::sim {

namespace {

// The cost of a cell that cannot be crossed (off the grid or lethal).
constexpr double kImpassable = std::numeric_limits<double>::infinity();

// The step cost of a cell, or +inf when it is off the grid or impassable; raises max_cost to its cost.
double crossing_cost(const CostmapGrid& grid, Cell c, const std::array<double, 256>& step_cost, int& max_cost) {
  if (!grid.in_bounds(c)) return kImpassable;
  const std::uint8_t value = grid.costs[grid.index(c)];
  max_cost = std::max(max_cost, static_cast<int>(value));
  return step_cost[value];
}

}  // namespace

double segment_cost(const CostmapGrid& grid, Cell a, Cell b, const std::array<double, 256>& step_cost,
                    int& max_cost) {
  max_cost = 0;
  double here = crossing_cost(grid, a, step_cost, max_cost);
  if (!std::isfinite(here)) return kImpassable;
  const int dc = b.col - a.col;
  const int dr = b.row - a.row;
  const long long adc = std::abs(dc);
  const long long adr = std::abs(dr);
  const int step_col = dc > 0 ? 1 : -1;
  const int step_row = dr > 0 ? 1 : -1;
  const double length = std::hypot(static_cast<double>(dc), static_cast<double>(dr));
  // Centre to centre, the segment crosses its k-th column boundary at t = (k + 1/2) / |dc| and its m-th row
  // boundary at (m + 1/2) / |dr|; comparing (1 + 2k) |dr| with (1 + 2m) |dc| in integers finds exact corners.
  constexpr long long kNever = std::numeric_limits<long long>::max();
  long long k = 0;
  long long m = 0;
  Cell c = a;
  double t_prev = 0.0;
  double cost = 0.0;
  while (c != b) {
    const long long col_key = adc == 0 ? kNever : (1 + 2 * k) * adr;
    const long long row_key = adr == 0 ? kNever : (1 + 2 * m) * adc;
    const double t = col_key <= row_key ? (0.5 + static_cast<double>(k)) / static_cast<double>(adc)
                                        : (0.5 + static_cast<double>(m)) / static_cast<double>(adr);
    // The stretch up to t lay in the cell being left.
    cost += (t - t_prev) * length * here;
    t_prev = t;
    if (col_key == row_key) {
      // Through a grid corner: both cells beside it must be passable, as for a diagonal step.
      if (!std::isfinite(crossing_cost(grid, {c.col + step_col, c.row}, step_cost, max_cost)) ||
          !std::isfinite(crossing_cost(grid, {c.col, c.row + step_row}, step_cost, max_cost))) {
        return kImpassable;
      }
    }
    if (col_key <= row_key) {
      c.col += step_col;
      ++k;
    }
    if (row_key <= col_key) {
      c.row += step_row;
      ++m;
    }
    here = crossing_cost(grid, c, step_cost, max_cost);
    if (!std::isfinite(here)) return kImpassable;
  }
  return cost + (1.0 - t_prev) * length * here;
}

std::vector<std::size_t> shortcut_corners(const CostmapGrid& grid, const std::vector<Cell>& cells,
                                          const std::vector<double>& g, const std::array<double, 256>& step_cost) {
  std::vector<std::size_t> corners;
  if (cells.empty()) return corners;
  const std::size_t last = cells.size() - 1;
  // Whether the segment from path cell i to path cell j may replace the path between them.
  const auto acceptable = [&](std::size_t i, std::size_t j) {
    int path_max = 0;
    for (std::size_t n = i; n <= j; ++n) path_max = std::max(path_max, static_cast<int>(grid.at(cells[n])));
    int line_max = 0;
    const double line = segment_cost(grid, cells[i], cells[j], step_cost, line_max);
    // A little slack for rounding: on free cells the line is strictly cheaper whenever it differs at all.
    return std::isfinite(line) && line_max <= path_max && line <= (g[j] - g[i]) * (1.0 + 1e-12) + 1e-9;
  };
  corners.push_back(0);
  std::size_t anchor = 0;
  while (anchor < last) {
    // The next path cell is always acceptable: it is the search's own step. Probe farther cells at doubling
    // distances, then bisect between the farthest accepted and the first refused. Acceptability is not
    // monotone along the path, so this finds a far acceptable cell, not always the farthest; every segment
    // kept has passed the test, which is what the guarantee rests on.
    std::size_t good = anchor + 1;
    std::size_t bad = last + 1;
    for (std::size_t stride = 2; anchor + stride <= last; stride *= 2) {
      if (!acceptable(anchor, anchor + stride)) {
        bad = anchor + stride;
        break;
      }
      good = anchor + stride;
    }
    if (bad > last && good < last) {
      if (acceptable(anchor, last)) {
        good = last;
      } else {
        bad = last;
      }
    }
    while (bad <= last && bad - good > 1) {
      const std::size_t mid = good + (bad - good) / 2;
      if (acceptable(anchor, mid)) {
        good = mid;
      } else {
        bad = mid;
      }
    }
    corners.push_back(good);
    anchor = good;
  }
  return corners;
}

}  // namespace rfbsim::sim
