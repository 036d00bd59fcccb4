// SPDX-License-Identifier: GPL-2.0-or-later
// GlobalPlanner: the robot's route from its pose to a goal over the global costmap, in the style of ROS
// global_planner: A* (or Dijkstra) over 8-connected cells, each step paid for by the cell it enters.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// How routes are searched (ROS global_planner's parameter names and defaults where one exists).
struct GlobalPlannerParams {
  double neutral_cost = 50.0;  ///< cost units for crossing one cell length of a free cell
  double cost_factor = 3.0;    ///< cost units added per unit of costmap cost: a cell costs neutral + factor * c
  int lethal_cost = 253;       ///< costmap cost at or above which a cell is impassable (1..255)
  bool use_dijkstra = false;   ///< true: plain Dijkstra (no heuristic); false: A* (same costs, fewer cells)
  bool allow_unknown = false;  ///< true: unknown cells (255) are passable at the highest traversal cost
  double default_tolerance = 0.0;  ///< m: a goal in a blocked cell moves to the nearest passable cell centre
                                   ///< within this distance; 0 refuses such goals
  bool simplify_path = false;  ///< rfbsim: straighten the grid path where that raises neither the max cell
                               ///< cost nor the cost along it (see path_shortcut.hpp); points stay dense
};

/// A planned route, or why there is none.
struct GlobalPlan {
  bool ok = false;
  /// World points (m) from the start to the goal, both included, one cell length apart or less (cell centres
  /// in between; with simplify_path, points along straight legs). The last point is the goal actually
  /// planned to: the asked goal, or the cell centre default_tolerance moved it to.
  std::vector<Eigen::Vector2d> path;
  double cost = 0.0;         ///< the grid path's cost: cell lengths times traversal cost (a free cell costs 50)
  std::string reason;        ///< why ok is false; empty when ok
  std::size_t expanded = 0;  ///< cells the search closed (how much work the plan took)
};

/// Plans on any CostmapGrid; keeps its search buffers between calls, so replanning on the same grid size
/// allocates nothing new. Not thread-safe: one planner per thread.
class GlobalPlanner {
 public:
  explicit GlobalPlanner(GlobalPlannerParams params = {});

  /// The cheapest 8-connected route from `start` to `goal` (world m) on `grid` (A*: within a billionth of
  /// the optimum, see the heuristic's comment). No diagonal step passes a blocked cell at its side. A start
  /// in a blocked cell (the robot pushed into inflation) may be left through the inscribed cells around it;
  /// a blocked goal is refused unless default_tolerance finds a passable cell near it. Never throws for bad
  /// input: ok = false with a reason.
  GlobalPlan plan(const CostmapGrid& grid, const Eigen::Vector2d& start, const Eigen::Vector2d& goal);

  [[nodiscard]] const GlobalPlannerParams& params() const { return params_; }
  void set_params(const GlobalPlannerParams& params) { params_ = params; }

 private:
  // A* / Dijkstra from start to goal cell; fills parent_ and g_, returns whether the goal was closed.
  bool search(const CostmapGrid& grid, Cell start, Cell goal, std::size_t& expanded);
  // The traversal cost per cell length of each costmap cost (infinite: impassable), from params_.
  void build_cost_table();

  GlobalPlannerParams params_;
  std::array<double, 256> step_cost_{};  // per costmap cost; +inf when impassable
  double escape_cost_ = 0.0;              // what an inscribed cell costs while leaving a blocked start
  struct OpenEntry {
    double f;
    double g;
    std::int32_t index;
  };
  std::vector<double> g_;              // cost from the start, per cell
  std::vector<std::int32_t> parent_;   // the cell a cell was reached from, -1 none
  std::vector<std::uint8_t> closed_;   // 1 once expanded
  std::vector<OpenEntry> open_;        // binary heap, lazily deleted
  std::vector<Cell> cells_;            // the last path's cells, start to goal
};

/// One-shot convenience: a fresh GlobalPlanner's plan (allocates its buffers every call).
GlobalPlan plan_path(const CostmapGrid& grid, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                     const GlobalPlannerParams& params = {});

}  // namespace rfbsim::sim
