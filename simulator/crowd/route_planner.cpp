// SPDX-License-Identifier: GPL-2.0-or-later
// RoutePlanner: A* over blocks of the obstacle grid within a clearance, then line-of-sight pruning to a few
// waypoints.
#include "crowd/route_planner.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <tuple>

namespace rfbsim::sim {

namespace {

constexpr std::size_t kNoParent = std::numeric_limits<std::size_t>::max();

// The cells of a k x k block as offsets from its lower-left corner, nearest the block's middle first
// (ties in row, then column order).
std::vector<Cell> middle_first_offsets(int k) {
  std::vector<Cell> offsets;
  for (int row = 0; row < k; ++row) {
    for (int col = 0; col < k; ++col) offsets.push_back({col, row});
  }
  const double middle = 0.5 * (k - 1);
  std::stable_sort(offsets.begin(), offsets.end(), [middle](Cell a, Cell b) {
    return std::hypot(a.col - middle, a.row - middle) < std::hypot(b.col - middle, b.row - middle);
  });
  return offsets;
}

}  // namespace

RoutePlanner::RoutePlanner(const GridMap& obstacles, RoutePlannerParams params)
    : field_(obstacles),
      params_(params),
      block_(std::max(1, static_cast<int>(std::lround(params.search_step / obstacles.resolution)))),
      block_offsets_(middle_first_offsets(block_)) {}

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
  // The start and goal cells may be narrower than the clearance: the person already stands there or must go.
  const auto open_cell = [&](Cell c) {
    return c == start || c == goal ? !m.is_occupied(c) : walkable(c, clearance);
  };
  if (!open_cell(start) || !open_cell(goal)) return {};

  // Nodes: blocks of k x k cells, each stood for by one of its open cells, except that the start's block
  // is stood for by the start; one more node is the goal itself. A 20 x 30 m map at 0.05 m has 240 000
  // cells but 15 000 blocks of 0.2 m, which makes a route across it some 15 times cheaper to find, and a
  // person needs no finer steps: the route is straightened afterwards on the cells themselves.
  const int k = block_;
  const int blocks_x = (m.width + k - 1) / k;
  const int blocks_y = (m.height + k - 1) / k;
  const std::size_t blocks = static_cast<std::size_t>(blocks_x) * static_cast<std::size_t>(blocks_y);
  const std::size_t goal_node = blocks;
  const auto node_of_block = [&](int bx, int by) {
    return static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_x) + static_cast<std::size_t>(bx);
  };
  const std::size_t start_node = node_of_block(start.col / k, start.row / k);
  // A block's stand-in is its open cell nearest the block's middle (scan order breaks ties), found on first
  // use: a passage narrower than a block still counts wherever it falls. A block without one is stood for
  // by its corner cell, which is not open, so the search never enters it.
  std::vector<Cell> stand_in(blocks, Cell{-1, -1});
  const auto cell_of_node = [&](std::size_t node) {
    if (node == goal_node) return goal;
    if (node == start_node) return start;
    Cell& cached = stand_in[node];
    if (cached.col < 0) {
      const Cell corner{static_cast<int>(node % static_cast<std::size_t>(blocks_x)) * k,
                        static_cast<int>(node / static_cast<std::size_t>(blocks_x)) * k};
      cached = corner;
      for (const Cell& offset : block_offsets_) {
        const Cell c{corner.col + offset.col, corner.row + offset.row};
        if (c.col < m.width && c.row < m.height && open_cell(c)) {
          cached = c;
          break;
        }
      }
    }
    return cached;
  };

  // A step between two open node cells: every cell on the segment must be open too, and where the segment
  // moves diagonally from one cell to the next, both cells beside that corner, so that no step slips
  // between two walls that touch at a corner. A step far from walls skips the check: the distance to walls
  // changes by at most the distance moved, so if both ends keep clearance + length / 2 (plus a cell for
  // the grid), every point between keeps the clearance.
  const auto step_open = [&](Cell a, Cell b) {
    const int dc = b.col - a.col;
    const int dr = b.row - a.row;
    const double length = res * std::hypot(dc, dr);
    const double roomy = clearance + 0.5 * length + res;
    if (field_.at_cell(a) - 0.5 * res >= roomy && field_.at_cell(b) - 0.5 * res >= roomy) return true;
    const int samples = static_cast<int>(std::ceil(2.0 * std::hypot(dc, dr)));  // every half cell
    Cell previous = a;
    for (int i = 1; i <= samples; ++i) {
      const double t = static_cast<double>(i) / samples;
      const Cell c{a.col + static_cast<int>(std::lround(t * dc)), a.row + static_cast<int>(std::lround(t * dr))};
      if (c == previous) continue;
      if (!open_cell(c)) return false;
      if (c.col != previous.col && c.row != previous.row &&
          (!open_cell({c.col, previous.row}) || !open_cell({previous.col, c.row}))) {
        return false;
      }
      previous = c;
    }
    return true;
  };
  // Cost per metre grows near walls so that routes keep to the middle of aisles where they can.
  const auto cost_factor = [&](Cell c) {
    const double surface = std::max(0.0, field_.at_cell(c) - 0.5 * res);
    return 1.0 + params_.wall_cost * std::max(0.0, 1.0 - surface / params_.comfort_distance);
  };
  const auto metres = [&](Cell a, Cell b) { return res * std::hypot(a.col - b.col, a.row - b.row); };

  std::vector<double> cost(blocks + 1, std::numeric_limits<double>::infinity());
  std::vector<std::size_t> parent(blocks + 1, kNoParent);
  std::vector<std::uint8_t> closed(blocks + 1, 0);
  // A* with the straight-line distance (admissible: every step costs at least its length), ordered by
  // (f, node): equal f values pop in node order, so the result never depends on the heap.
  using Entry = std::tuple<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  const auto relax = [&](std::size_t from, Cell from_cell, std::size_t to, Cell to_cell) {
    if (closed[to] != 0 || !open_cell(to_cell) || !step_open(from_cell, to_cell)) return;
    const double step = metres(from_cell, to_cell) * 0.5 * (cost_factor(from_cell) + cost_factor(to_cell));
    const double total = cost[from] + step;
    if (total < cost[to]) {
      cost[to] = total;
      parent[to] = from;
      open.emplace(total + metres(to_cell, goal), to);
    }
  };
  const int goal_bx = goal.col / k;
  const int goal_by = goal.row / k;
  cost[start_node] = 0.0;
  open.emplace(metres(start, goal), start_node);
  while (!open.empty()) {
    const std::size_t at = std::get<1>(open.top());
    open.pop();
    if (closed[at] != 0) continue;
    closed[at] = 1;
    if (at == goal_node) break;
    const Cell c = cell_of_node(at);
    const int bx = static_cast<int>(at % static_cast<std::size_t>(blocks_x));
    const int by = static_cast<int>(at / static_cast<std::size_t>(blocks_x));
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = bx + dx;
        const int ny = by + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= blocks_x || ny >= blocks_y) continue;
        const std::size_t n = node_of_block(nx, ny);
        relax(at, c, n, cell_of_node(n));
      }
    }
    // The goal node joins its own block and the eight around it.
    if (std::abs(bx - goal_bx) <= 1 && std::abs(by - goal_by) <= 1) relax(at, c, goal_node, goal);
  }
  if (closed[goal_node] == 0) return {};
  std::vector<Cell> path;
  for (std::size_t node = goal_node; node != kNoParent; node = parent[node]) path.push_back(cell_of_node(node));
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
