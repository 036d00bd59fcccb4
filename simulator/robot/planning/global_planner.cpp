// SPDX-License-Identifier: GPL-2.0-or-later
// GlobalPlanner: input checks, the goal tolerance, an A*/Dijkstra search over flat reusable buffers, and the
// path as world points.
#include "robot/planning/global_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "robot/planning/grid_neighbours.hpp"
#include "robot/planning/grid_point.hpp"
#include "robot/planning/path_shortcut.hpp"

namespace rfbsim::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSqrt2 = 1.4142135623730951;

// "(1.25, -0.50)" for reasons.
std::string point_text(const Eigen::Vector2d& p) {
  char text[64];
  std::snprintf(text, sizeof text, "(%.2f, %.2f)", p.x(), p.y());
  return text;
}

std::string extent_text(const CostmapGrid& grid) {
  char text[96];
  std::snprintf(text, sizeof text, "x %.2f..%.2f, y %.2f..%.2f m", grid.origin_x,
                grid.origin_x + grid.width * grid.resolution, grid.origin_y,
                grid.origin_y + grid.height * grid.resolution);
  return text;
}

// Max-heap order that pops the lowest f first; among equal f the deeper node (higher g), then the lower
// index, so the result never depends on the heap's internals. A function object, so that the heap
// operations inline it.
struct PopsLater {
  template <typename Entry>
  bool operator()(const Entry& a, const Entry& b) const {
    if (a.f != b.f) return a.f > b.f;
    if (a.g != b.g) return a.g < b.g;
    return a.index > b.index;
  }
};

GlobalPlan failure(std::string reason, std::size_t expanded = 0) {
  GlobalPlan plan;
  plan.reason = std::move(reason);
  plan.expanded = expanded;
  return plan;
}

}  // namespace

GlobalPlanner::GlobalPlanner(GlobalPlannerParams params) : params_(params) {}

void GlobalPlanner::build_cost_table() {
  // global_planner's cell cost: neutral + factor * c, capped one below lethal so that no passable cell costs
  // as much as an impassable one (docs/sources.md: 50 + 3c capped at 252).
  const double cap = std::max(1, params_.lethal_cost - 1);
  for (int c = 0; c < 256; ++c) {
    const bool unknown_ok = params_.allow_unknown && c == cost::kUnknown;
    step_cost_[static_cast<std::size_t>(c)] =
        c >= params_.lethal_cost && !unknown_ok ? kInf : std::min(params_.neutral_cost + params_.cost_factor * c, cap);
  }
  escape_cost_ = cap;
}

GlobalPlan GlobalPlanner::plan(const CostmapGrid& grid, const Eigen::Vector2d& start, const Eigen::Vector2d& goal) {
  // Parameters and grid first: a bad one would make every cost below meaningless.
  if (!(params_.neutral_cost > 0.0) || !std::isfinite(params_.neutral_cost) || !(params_.cost_factor >= 0.0) ||
      !std::isfinite(params_.cost_factor) || params_.lethal_cost < 1 || params_.lethal_cost > 255 ||
      !(params_.default_tolerance >= 0.0) || !std::isfinite(params_.default_tolerance)) {
    return failure("bad planner parameters: need neutral_cost > 0, cost_factor >= 0, lethal_cost 1..255, "
                   "default_tolerance >= 0");
  }
  if (grid.width <= 0 || grid.height <= 0 || !(grid.resolution > 0.0) ||
      grid.costs.size() != static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height)) {
    return failure("the costmap is empty or its cost array does not match its size");
  }
  if (grid.costs.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return failure("the costmap has more cells than the planner can index");
  }
  if (!start.allFinite()) return failure("start is not a finite point");
  if (!goal.allFinite()) return failure("goal is not a finite point");
  if (!on_grid(grid, start.x(), start.y())) return failure("start " + point_text(start) + " is off the costmap (" + extent_text(grid) + ")");
  if (!on_grid(grid, goal.x(), goal.y())) return failure("goal " + point_text(goal) + " is off the costmap (" + extent_text(grid) + ")");
  const Cell start_cell = grid.cell_of(start.x(), start.y());
  const Cell asked_goal_cell = grid.cell_of(goal.x(), goal.y());
  build_cost_table();

  // A goal in a blocked cell moves to the nearest passable cell centre within default_tolerance (ties: the
  // lowest row, then column), or is refused.
  Cell goal_cell = asked_goal_cell;
  Eigen::Vector2d goal_point = goal;
  const std::uint8_t goal_cost = grid.at(goal_cell);
  if (!std::isfinite(step_cost_[goal_cost])) {
    const std::string blocked = "goal " + point_text(goal) + " is in an obstacle (cost " + std::to_string(goal_cost) + ")";
    const double tolerance = params_.default_tolerance;
    // Rings of cells around the goal's, no more than the grid has.
    const int rings = static_cast<int>(std::min(std::ceil(tolerance / grid.resolution), static_cast<double>(std::max(grid.width, grid.height)))) + 1;
    double best = kInf;
    for (int row = goal_cell.row - rings; row <= goal_cell.row + rings; ++row) {
      for (int col = goal_cell.col - rings; col <= goal_cell.col + rings; ++col) {
        const Cell c{col, row};
        if (!grid.in_bounds(c) || !std::isfinite(step_cost_[grid.at(c)])) continue;
        const double d = (grid.cell_centre(c) - goal).norm();
        if (d <= tolerance && d < best) {
          best = d;
          goal_cell = c;
        }
      }
    }
    if (!std::isfinite(best)) {
      if (tolerance <= 0.0) return failure(blocked);
      char within[48];
      std::snprintf(within, sizeof within, " and no passable cell lies within %.2f m", tolerance);
      return failure(blocked + within);
    }
    goal_point = grid.cell_centre(goal_cell);
  }

  // Start and goal in one cell: nothing to search.
  GlobalPlan result;
  if (start_cell == goal_cell) {
    result.ok = true;
    result.path = {start, goal_point};
    return result;
  }
  std::size_t expanded = 0;
  if (!search(grid, start_cell, goal_cell, expanded)) {
    std::string reason = "goal unreachable: searched " + std::to_string(expanded) + " cells";
    const std::uint8_t start_cost = grid.at(start_cell);
    if (!std::isfinite(step_cost_[start_cost])) {
      reason += " (the start " + point_text(start) + " is in an obstacle, cost " + std::to_string(start_cost) + ")";
    }
    return failure(std::move(reason), expanded);
  }

  // The cells from start to goal, by the parents.
  cells_.clear();
  for (std::int32_t at = static_cast<std::int32_t>(grid.index(goal_cell)); at >= 0; at = parent_[static_cast<std::size_t>(at)]) {
    cells_.push_back({at % grid.width, at / grid.width});
  }
  std::reverse(cells_.begin(), cells_.end());
  result.ok = true;
  result.cost = g_[grid.index(goal_cell)];
  result.expanded = expanded;

  // World points: the exact start, cell centres, the goal; or, simplified, straight legs between corner
  // cells sampled every cell length so that the path stays as dense as a grid path.
  result.path.reserve(cells_.size() + 1);
  result.path.push_back(start);
  if (!params_.simplify_path) {
    for (std::size_t i = 1; i + 1 < cells_.size(); ++i) result.path.push_back(grid.cell_centre(cells_[i]));
  } else {
    std::vector<double> g(cells_.size());
    for (std::size_t i = 0; i < cells_.size(); ++i) g[i] = g_[grid.index(cells_[i])];
    const std::vector<std::size_t> corners = shortcut_corners(grid, cells_, g, step_cost_);
    for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
      const Eigen::Vector2d a = grid.cell_centre(cells_[corners[k]]);
      const Eigen::Vector2d b = grid.cell_centre(cells_[corners[k + 1]]);
      const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / grid.resolution - 1e-9)));
      // The first leg starts at the exact start point, already in the path.
      for (int i = k == 0 ? 1 : 0; i < pieces; ++i) result.path.push_back(a + (b - a) * (static_cast<double>(i) / pieces));
    }
  }
  result.path.push_back(goal_point);
  return result;
}

bool GlobalPlanner::search(const CostmapGrid& grid, Cell start, Cell goal, std::size_t& expanded) {
  const std::size_t n = grid.costs.size();
  g_.assign(n, kInf);
  parent_.assign(n, -1);
  closed_.assign(n, 0);
  open_.clear();
  const int width = grid.width;
  const int height = grid.height;
  const std::uint8_t* costs = grid.costs.data();

  // A* with the octile distance (the length of the shortest 8-connected route on an empty grid: straight
  // steps plus sqrt 2 per diagonal one) times the cheapest step cost. No route is shorter and no cell is
  // cheaper, so it never overestimates, and it is consistent; it is exact in free space, where the
  // straight-line distance would leave A* searching a wide ellipse. Dijkstra: no heuristic.
  // Scaled up by a billionth: on open floor countless routes tie at the optimal cost, and rounding makes
  // their f values differ at random, so that A* would close the whole band between them. The nudge breaks
  // ties toward the goal; the path found costs at most a billionth over the optimum.
  const double h_scale = params_.use_dijkstra ? 0.0 : std::min(step_cost_[0], escape_cost_) * (1.0 + 1e-9);
  const auto heuristic = [&](int col, int row) {
    const int dc = std::abs(col - goal.col);
    const int dr = std::abs(row - goal.row);
    return h_scale * (std::max(dc, dr) + (kSqrt2 - 1.0) * std::min(dc, dr));
  };
  // What entering a cell of costmap cost c costs per cell length: its step cost; from a blocked cell (only
  // the start and the inscribed cells around it) an inscribed cell costs the most a passable cell can, so a
  // robot pushed into inflation can drive out; a lethal or forbidden unknown cell can never be entered.
  const auto enter_cost = [&](bool from_blocked, std::uint8_t c) {
    const double step = step_cost_[c];
    if (std::isfinite(step) || !from_blocked) return step;
    return c >= params_.lethal_cost && c < cost::kLethal ? escape_cost_ : kInf;
  };

  const std::size_t start_index = grid.index(start);
  const std::size_t goal_index = grid.index(goal);
  g_[start_index] = 0.0;
  open_.push_back({heuristic(start.col, start.row), 0.0, static_cast<std::int32_t>(start_index)});
  while (!open_.empty()) {
    std::pop_heap(open_.begin(), open_.end(), PopsLater{});
    const OpenEntry top = open_.back();
    open_.pop_back();
    const auto at = static_cast<std::size_t>(top.index);
    if (closed_[at] != 0) continue;  // a stale entry: the cell was reached cheaper before
    closed_[at] = 1;
    ++expanded;
    if (at == goal_index) return true;
    const int col = top.index % width;
    const int row = top.index / width;
    const bool from_blocked = !std::isfinite(step_cost_[costs[at]]);
    for (int k = 0; k < 8; ++k) {
      const int ncol = col + kNeighbourDc[k];
      const int nrow = row + kNeighbourDr[k];
      if (ncol < 0 || nrow < 0 || ncol >= width || nrow >= height) continue;
      const std::size_t next = static_cast<std::size_t>(nrow) * static_cast<std::size_t>(width) + static_cast<std::size_t>(ncol);
      if (closed_[next] != 0) continue;
      double step = enter_cost(from_blocked, costs[next]);
      if (!std::isfinite(step)) continue;
      if (k >= 4) {
        // No corner cutting: a diagonal step needs both cells beside it enterable too.
        const std::size_t side_a = static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(ncol);
        const std::size_t side_b = static_cast<std::size_t>(nrow) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col);
        if (!std::isfinite(enter_cost(from_blocked, costs[side_a])) || !std::isfinite(enter_cost(from_blocked, costs[side_b]))) continue;
        step *= kSqrt2;
      }
      const double g = top.g + step;
      if (g < g_[next]) {
        g_[next] = g;
        parent_[next] = top.index;
        open_.push_back({g + heuristic(ncol, nrow), g, static_cast<std::int32_t>(next)});
        std::push_heap(open_.begin(), open_.end(), PopsLater{});
      }
    }
  }
  return false;
}

GlobalPlan plan_path(const CostmapGrid& grid, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                     const GlobalPlannerParams& params) {
  GlobalPlanner planner(params);
  return planner.plan(grid, start, goal);
}

}  // namespace rfbsim::sim
