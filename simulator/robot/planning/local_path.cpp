// SPDX-License-Identifier: GPL-2.0-or-later
// Local path: the nearest path point within a horizon, and the walk along the path while it stays on the grid.
#include "robot/planning/local_path.hpp"

#include "robot/planning/grid_point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rfbsim::sim {

LocalPathCut cut_local_path(const std::vector<Eigen::Vector2d>& path, std::size_t from, double horizon,
                            const CostmapGrid& grid, const Eigen::Vector2d& robot, std::vector<std::int32_t>& cells) {
  cells.clear();
  LocalPathCut cut;
  if (path.empty()) {
    cut.reason = "no global path set";
    return cut;
  }
  // The nearest point from `from` onward, looking no farther along the path than the horizon.
  from = std::min(from, path.size() - 1);
  double best = (path[from] - robot).squaredNorm();
  cut.nearest = from;
  double along = 0.0;
  for (std::size_t i = from + 1; i < path.size(); ++i) {
    along += (path[i] - path[i - 1]).norm();
    if (along > horizon) break;
    const double d = (path[i] - robot).squaredNorm();
    if (d < best) {
      best = d;
      cut.nearest = i;
    }
  }
  const Eigen::Vector2d& start = path[cut.nearest];
  if (!on_grid(grid, start.x(), start.y())) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the global path leaves the local costmap at the robot: its nearest point (%.2f, %.2f) is %.2f m "
                  "away, off the costmap",
                  start.x(), start.y(), std::sqrt(best));
    cut.reason = text;
    return cut;
  }

  // Walk on every half cell; stop at the first step off the grid. Consecutive repeats are skipped (the
  // distance grid would ignore them anyway).
  const double step = 0.5 * grid.resolution;
  const auto visit = [&](const Eigen::Vector2d& p) {
    if (!on_grid(grid, p.x(), p.y())) return false;
    const Cell c = grid.cell_of(p.x(), p.y());
    const auto index = static_cast<std::int32_t>(grid.index(c));
    if (cells.empty() || cells.back() != index) cells.push_back(index);
    cut.local_goal = p;
    return true;
  };
  visit(start);
  cut.ends_at_goal = true;
  for (std::size_t i = cut.nearest + 1; i < path.size() && cut.ends_at_goal; ++i) {
    const Eigen::Vector2d a = path[i - 1];
    const Eigen::Vector2d b = path[i];
    const double length = (b - a).norm();
    // Capped so that an absurdly long segment cannot overflow the count; the walk leaves the grid long before.
    const int pieces = std::max(1, static_cast<int>(std::min(std::ceil(length / step), 1e9)));
    for (int k = 1; k <= pieces; ++k) {
      if (!visit(a + (b - a) * (static_cast<double>(k) / pieces))) {
        cut.ends_at_goal = false;
        break;
      }
    }
  }
  cut.ok = true;
  return cut;
}

}  // namespace rfbsim::sim
