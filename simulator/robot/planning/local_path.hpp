// SPDX-License-Identifier: GPL-2.0-or-later
// Local path: the stretch of the global path that the local planner steers by on its rolling costmap window,
// and the local goal at its end.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// Where the global path meets the local costmap.
struct LocalPathCut {
  bool ok = false;
  std::string reason;        ///< why ok is false
  std::size_t nearest = 0;   ///< index of the global-path point nearest the robot
  Eigen::Vector2d local_goal = Eigen::Vector2d::Zero();  ///< m: the last point of the stretch on the grid
  bool ends_at_goal = false;  ///< whether the local goal is the global path's last point
};

/// Finds the global-path point nearest `robot` among the points from index `from` onward that lie within
/// `horizon` m of path length of it (so a path that doubles back past the robot is not jumped along), then
/// walks the path from that point every half cell for as long as it stays on `grid`, putting each cell it
/// crosses into `cells` (cleared first; cell indices into `grid`). Fails with a reason when the path is
/// empty or its point nearest the robot lies off the grid.
LocalPathCut cut_local_path(const std::vector<Eigen::Vector2d>& path, std::size_t from, double horizon,
                            const CostmapGrid& grid, const Eigen::Vector2d& robot, std::vector<std::int32_t>& cells);

}  // namespace rfbsim::sim
