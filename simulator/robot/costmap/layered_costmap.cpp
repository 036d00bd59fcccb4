// SPDX-License-Identifier: GPL-2.0-or-later
// LayeredCostmap: building the layers, re-centring a rolling window, and the bounds-then-costs update.
#include "robot/costmap/layered_costmap.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace rfbsim::sim {

namespace {

// The parameters, once validate() has passed them (it throws otherwise).
const CostmapParams& checked(const CostmapParams& params) {
  validate(params);
  return params;
}

// Cells of the frame's margin: at least the inflation's reach, so that the map's outside (lethal) inflates
// into the map exactly as a wall there would.
int margin_cells(const CostmapParams& p) {
  return static_cast<int>(std::ceil(p.inflation.inflation_radius / p.resolution)) + 1;
}

// Whole cells in `metres` (validate() bounds the count).
int cells(double metres, double resolution) {
  return std::max(1, static_cast<int>(std::lround(metres / resolution)));
}

}  // namespace

LayeredCostmap::LayeredCostmap(const GridMap& static_map, CostmapParams params)
    : params_(checked(params)), frame_(frame_for_map(static_map, params_.resolution, margin_cells(params_))) {
  if (params_.use_static_layer) static_.emplace(static_map, frame_);
  if (params_.use_obstacle_layer) obstacle_.emplace(params_.obstacle, frame_, params_.robot_radius);
  if (params_.use_inflation_layer) {
    inflation_.emplace(params_.inflation, params_.robot_radius, params_.resolution);
    if (static_) inflation_->cache_static(*static_);
  }
  if (params_.use_proxemic_layer) proxemic_.emplace(params_.proxemic);

  if (params_.rolling_window) {
    master_ = CostmapGrid::sized(cells(params_.width, params_.resolution), cells(params_.height, params_.resolution),
                                 params_.resolution, 0.0, 0.0);
    const Eigen::Vector2d middle = frame_.cell_centre({frame_.width / 2, frame_.height / 2});
    recentre(middle.x(), middle.y());
  } else {
    // The global costmap is the frame without its margin.
    const int margin = margin_cells(params_);
    offset_ = {margin, margin};
    master_ = CostmapGrid::sized(frame_.width - 2 * margin, frame_.height - 2 * margin, params_.resolution,
                                 frame_.origin_x + margin * params_.resolution,
                                 frame_.origin_y + margin * params_.resolution);
  }
  social_ = master_;
  frame_.costs = {};  // geometry only: the layers hold their own cells
}

void LayeredCostmap::recentre(double x, double y) {
  // Clamped in floating point before the cast: a pose far off the map cannot overflow the index.
  const auto index = [](double v) { return static_cast<int>(std::floor(std::clamp(v, -1e7, 1e7))); };
  offset_ = {index((x - frame_.origin_x) / frame_.resolution) - master_.width / 2,
             index((y - frame_.origin_y) / frame_.resolution) - master_.height / 2};
  master_.origin_x = frame_.origin_x + offset_.col * frame_.resolution;
  master_.origin_y = frame_.origin_y + offset_.row * frame_.resolution;
  social_.origin_x = master_.origin_x;
  social_.origin_y = master_.origin_y;
}

CostmapUpdateReport LayeredCostmap::update(const Pose2& robot_pose, const LaserScan* scan,
                                           std::span<const SeenPerson> people) {
  CostmapUpdateReport report;
  const bool pose_ok = std::isfinite(robot_pose.x) && std::isfinite(robot_pose.y) && std::isfinite(robot_pose.yaw);
  if (params_.rolling_window && pose_ok) recentre(robot_pose.x, robot_pose.y);

  // Inputs: the scan into the obstacle marks (then the footprint cleared), the people into the proxemic layer.
  if (!obstacle_) {
    report.scan_skipped = "obstacle layer off";
  } else if (scan == nullptr) {
    report.scan_skipped = "no scan";
  } else if (!pose_ok) {
    report.scan_skipped = "robot pose is not finite";
  } else if (!obstacle_->add_scan(robot_pose, *scan)) {
    report.scan_skipped = "scan angles are not finite";
  } else {
    report.scan_used = true;
  }
  if (obstacle_ && pose_ok) obstacle_->clear_footprint(robot_pose.x, robot_pose.y);
  if (proxemic_) report.people_used = proxemic_->set_people(people);

  // Bounds: each layer grows the dirty window (frame cells); the inflation layer last, by its reach.
  CellWindow bounds = CellWindow::none();
  if (static_) static_->update_bounds(bounds);
  if (obstacle_) obstacle_->update_bounds(bounds);
  if (proxemic_) proxemic_->update_bounds(frame_, bounds);
  if (inflation_) inflation_->update_bounds(bounds);

  // A rolling window moved under everything: all of it is dirty. So is the first update of any costmap.
  CellWindow window = frame_to_master(bounds, offset_, master_);
  if (params_.rolling_window || !written_) window = CellWindow::whole(master_.width, master_.height);
  written_ = true;
  write_costs(window);
  report.window = window;
  return report;
}

void LayeredCostmap::write_costs(const CellWindow& window) {
  if (window.empty()) return;
  // The contract every layer relies on: the window lies inside the master (the bounds were clipped).
  assert(window.min_col >= 0 && window.min_row >= 0 && window.max_col < master_.width &&
         window.max_row < master_.height && "costmap: dirty window outside the master grid");
  for (int row = window.min_row; row <= window.max_row; ++row) {
    std::uint8_t* cells_in_row = &master_.costs[master_.index({window.min_col, row})];
    std::fill(cells_in_row, cells_in_row + window.columns(), cost::kFree);
  }
  if (static_) static_->update_costs(master_, window, offset_);
  if (obstacle_) obstacle_->update_costs(master_, window, offset_);
  if (inflation_) {
    inflation_->update_costs(master_, window, offset_, static_ ? &*static_ : nullptr,
                             obstacle_ ? &*obstacle_ : nullptr);
  }
  if (proxemic_) proxemic_->update_costs(master_, social_, window);
}

void LayeredCostmap::refresh_obstacles() {
  CellWindow bounds = CellWindow::none();
  obstacle_->update_bounds(bounds);
  if (inflation_) inflation_->update_bounds(bounds);
  write_costs(params_.rolling_window ? CellWindow::whole(master_.width, master_.height)
                                     : frame_to_master(bounds, offset_, master_));
}

int LayeredCostmap::clear_obstacles_beyond(const Eigen::Vector2d& centre, double distance) {
  if (!obstacle_) return 0;
  const int dropped = obstacle_->clear_beyond(centre, distance);
  refresh_obstacles();
  return dropped;
}

void LayeredCostmap::clear_obstacles() {
  if (!obstacle_) return;
  obstacle_->clear_all();
  refresh_obstacles();
}

}  // namespace rfbsim::sim
