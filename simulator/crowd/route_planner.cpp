// SPDX-License-Identifier: GPL-2.0-or-later
// RoutePlanner: A* on the obstacle grid within a clearance, then line-of-sight pruning to a few waypoints.
#include "crowd/route_planner.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <tuple>

namespace rfbsim::sim {

namespace {

std::size_t index_of(const GridMap& map, Cell c) {
  return static_cast<std::size_t>(c.row) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(c.col);
}

}  // namespace

RoutePlanner::RoutePlanner(const GridMap& obstacles, RoutePlannerParams params)
    : field_(obstacles), params_(params) {}

bool RoutePlanner::walkable(Cell c, double clearance) const {
  // at_cell is centre to centre; the nearest wall's surface is half a cell nearer.
  return !map().is_occupied(c) && field_.at_cell(c) - 0.5 * map().resolution >= clearance - 1e-9;
}

Eigen::Vector2d RoutePlanner::nearest_free(const Eigen::Vector2d& p, int max_cells) const {
  const GridMap& m = map();
  const Cell c = m.cell_of(p.x(), p.y());
  if (!m.is_occupied(c)) return p;
  // Ring by ring; within a ring the first cell by distance, then by (row, col), so ties break the same way.
  for (int ring = 1; ring <= max_cells; ++ring) {
    double best = std::numeric_limits<double>::infinity();
    Cell found{};
    bool any = false;
    for (int dr = -ring; dr <= ring; ++dr) {
      for (int dc = -ring; dc <= ring; ++dc) {
        if (std::max(std::abs(dr), std::abs(dc)) != ring) continue;
        const Cell n{c.col + dc, c.row + dr};
        if (m.is_occupied(n)) continue;
        const double d = (m.cell_centre(n) - p).squaredNorm();
        if (d < best) {
          best = d;
          found = n;
          any = true;
        }
      }
    }
    if (any) return m.cell_centre(found);
  }
  return p;
}

std::vector<Cell> RoutePlanner::search(Cell start, Cell goal, double clearance) const {
  const GridMap& m = map();
  const double res = m.resolution;
  const std::size_t cells = static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height);
  // The start and goal cells may be narrower than the clearance: the person already stands there or must go.
  const auto open_cell = [&](Cell c) {
    return c == start || c == goal ? !m.is_occupied(c) : walkable(c, clearance);
  };
  if (!open_cell(start) || !open_cell(goal)) return {};
  // Cost per metre grows near walls so that routes keep to the middle of aisles where they can.
  const auto cost_factor = [&](Cell c) {
    const double surface = std::max(0.0, field_.at_cell(c) - 0.5 * res);
    return 1.0 + params_.wall_cost * std::max(0.0, 1.0 - surface / params_.comfort_distance);
  };
  const auto heuristic = [&](Cell c) {  // octile distance: admissible, every step costs at least its length
    const double dx = std::abs(c.col - goal.col);
    const double dy = std::abs(c.row - goal.row);
    return res * (std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy));
  };
  std::vector<double> cost(cells, std::numeric_limits<double>::infinity());
  std::vector<int> parent(cells, -1);
  std::vector<std::uint8_t> closed(cells, 0);
  // Ordered by (f, cell index): equal f values pop in index order, so the result never depends on the heap.
  using Entry = std::tuple<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  cost[index_of(m, start)] = 0.0;
  open.emplace(heuristic(start), index_of(m, start));
  constexpr int kDc[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  constexpr int kDr[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  while (!open.empty()) {
    const std::size_t at = std::get<1>(open.top());
    open.pop();
    if (closed[at] != 0) continue;
    closed[at] = 1;
    const Cell c{static_cast<int>(at % static_cast<std::size_t>(m.width)),
                 static_cast<int>(at / static_cast<std::size_t>(m.width))};
    if (c == goal) break;
    for (int k = 0; k < 8; ++k) {
      const Cell n{c.col + kDc[k], c.row + kDr[k]};
      if (n.col < 0 || n.row < 0 || n.col >= m.width || n.row >= m.height || !open_cell(n)) continue;
      const bool diagonal = k >= 4;
      // No corner cutting: a diagonal step needs both cells it passes between to be open too.
      if (diagonal && (!open_cell({c.col + kDc[k], c.row}) || !open_cell({c.col, c.row + kDr[k]}))) continue;
      const std::size_t ni = index_of(m, n);
      const double step = (diagonal ? std::sqrt(2.0) : 1.0) * res * 0.5 * (cost_factor(c) + cost_factor(n));
      if (cost[at] + step < cost[ni]) {
        cost[ni] = cost[at] + step;
        parent[ni] = static_cast<int>(at);
        open.emplace(cost[ni] + heuristic(n), ni);
      }
    }
  }
  if (parent[index_of(m, goal)] < 0 && !(start == goal)) return {};
  std::vector<Cell> path;
  for (int i = static_cast<int>(index_of(m, goal)); i >= 0; i = parent[static_cast<std::size_t>(i)]) {
    path.push_back({i % m.width, i / m.width});
  }
  std::reverse(path.begin(), path.end());
  return path;
}

bool RoutePlanner::line_clear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance) const {
  const GridMap& m = map();
  const Cell ca = m.cell_of(a.x(), a.y());
  const Cell cb = m.cell_of(b.x(), b.y());
  const double length = (b - a).norm();
  const int samples = std::max(1, static_cast<int>(std::ceil(length / (0.5 * m.resolution))));
  for (int i = 0; i <= samples; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / samples);
    const Cell c = m.cell_of(p.x(), p.y());
    if (c == ca || c == cb) {
      if (m.is_occupied(c)) return false;
      continue;
    }
    if (!walkable(c, clearance)) return false;
  }
  return true;
}

PlannedRoute RoutePlanner::plan(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double clearance) const {
  const GridMap& m = map();
  if (m.width <= 0 || m.height <= 0) return {{to}, 0.0};
  const Eigen::Vector2d start_point = nearest_free(from);
  const Eigen::Vector2d goal_point = nearest_free(to);
  const Cell start = m.cell_of(start_point.x(), start_point.y());
  const Cell goal = m.cell_of(goal_point.x(), goal_point.y());
  // The widest clearance that has a path: the asked one, half of it, then any free cells.
  for (const double c : {clearance, 0.5 * clearance, 0.0}) {
    const std::vector<Cell> cells = search(start, goal, c);
    if (cells.empty()) continue;
    // Cell centres, from where the person stands to the exact goal.
    std::vector<Eigen::Vector2d> points;
    points.reserve(cells.size() + 1);
    points.push_back(from);
    for (std::size_t i = 1; i + 1 < cells.size(); ++i) points.push_back(m.cell_centre(cells[i]));
    points.push_back(goal_point);
    // Line-of-sight pruning: from each kept point, go as far along the path as is straight-line walkable.
    PlannedRoute route;
    route.clearance = c;
    std::size_t anchor = 0;
    while (anchor + 1 < points.size()) {
      std::size_t reach = anchor + 1;
      while (reach + 1 < points.size() && line_clear(points[anchor], points[reach + 1], c)) ++reach;
      route.waypoints.push_back(points[reach]);
      anchor = reach;
    }
    if (route.waypoints.empty()) route.waypoints.push_back(goal_point);
    return route;
  }
  return {};
}

}  // namespace rfbsim::sim
