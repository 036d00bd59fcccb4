// SPDX-License-Identifier: GPL-2.0-or-later
// ObstacleLayer: what the lidar sees (costmap_2d's ObstacleLayer). Each scan clears the cells its beams
// cross and marks the cells its returns land in; marks persist, world-anchored in the costmap frame, until
// a later beam crosses them or the navigator clears them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <vector>

#include "robot/costmap/cell_window.hpp"
#include "robot/costmap/costmap_frame.hpp"
#include "robot/costmap/costmap_grid.hpp"
#include "robot/costmap/costmap_params.hpp"
#include "robot/sensing/laser_scan.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

class ObstacleLayer {
 public:
  /// No marks yet, on `frame`'s cells (its geometry only); `footprint_radius` m around the robot is never
  /// marked.
  ObstacleLayer(const ObstacleLayerParams& params, const CostmapGrid& frame, double footprint_radius);

  /// Takes one scan from a sensor at `pose` (the robot's estimated pose; beam i points at pose.yaw +
  /// angle_min + i * angle_increment): first every beam clears the cells it crosses, up to its return
  /// (that cell excluded) or raytrace_range, then every return within obstacle_range marks its cell
  /// lethal. A range of range_max or more is no return (clears, marks nothing); NaN, negative or below
  /// range_min is skipped. Returns false, changing nothing, when the pose or the scan's angles are not finite.
  bool add_scan(const Pose2& pose, const LaserScan& scan);
  /// Clears every mark within the footprint: cells whose centre is within footprint_radius of (x, y),
  /// and the cell holding (x, y). Nothing for a non-finite position.
  void clear_footprint(double x, double y);
  /// Drops every mark whose cell centre is farther than `distance` m from `centre` (the navigator's
  /// "clear costmap" recovery); returns how many. Nothing for non-finite arguments.
  int clear_beyond(const Eigen::Vector2d& centre, double distance);
  /// Drops every mark.
  void clear_all();

  /// The marks on the frame's cells: cost::kLethal where marked, cost::kFree elsewhere.
  [[nodiscard]] const CostmapGrid& marks() const { return marks_; }
  /// Whether the cell holding world point (x, y) is marked (false beyond the frame).
  [[nodiscard]] bool is_marked_at(double x, double y) const { return marks_.at_world(x, y, cost::kFree) != 0; }
  /// How many cells are marked.
  [[nodiscard]] int mark_count() const { return mark_count_; }

  /// Bounds: grows `frame_bounds` by every cell marked or cleared since the last call, then forgets them.
  void update_bounds(CellWindow& frame_bounds);
  /// Writes the marks inside `window` of `master` as lethal.
  void update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset) const;

  /// Calls f(frame_cell) for every mark inside `frame_window` (clipped to the frame), row by row.
  template <class F>
  void for_each_mark(const CellWindow& frame_window, F&& f) const;

 private:
  // Clears the cells of one ray from (x, y) (frame cell units) along (dx, dy) for `length` cells; the last
  // cell (the one holding the end point) too unless `keep_last`.
  void clear_ray(double x, double y, double dx, double dy, double length, bool keep_last);
  void mark(Cell c);
  void clear(Cell c) {
    if (!marks_.in_bounds(c)) return;
    std::uint8_t& m = marks_.costs[marks_.index(c)];
    if (m == cost::kFree) return;
    m = cost::kFree;
    --mark_count_;
    changed_.include(c);
  }

  ObstacleLayerParams params_;
  double footprint_radius_;
  CostmapGrid marks_;
  int mark_count_ = 0;
  CellWindow changed_;  // cells marked or cleared since update_bounds last ran
  CellWindow marked_;   // holds every mark (maybe more): where clear_beyond and clear_all look
  std::vector<Cell> hits_;  // reused: the cells one scan marks, after its clearing pass
};

template <class F>
void ObstacleLayer::for_each_mark(const CellWindow& frame_window, F&& f) const {
  if (mark_count_ == 0) return;
  const CellWindow w = frame_window.clipped(marks_.width, marks_.height);
  if (w.empty()) return;
  for (int row = w.min_row; row <= w.max_row; ++row) {
    const std::uint8_t* cells = &marks_.costs[marks_.index({0, row})];
    int col = w.min_col;
    // Marks are sparse: skip eight free cells at a time.
    for (; col + 8 <= w.max_col + 1; col += 8) {
      std::uint64_t eight = 0;
      std::memcpy(&eight, cells + col, sizeof eight);
      if (eight == 0) continue;
      for (int k = col; k < col + 8; ++k) {
        if (cells[k] != 0) f(Cell{k, row});
      }
    }
    for (; col <= w.max_col; ++col) {
      if (cells[col] != 0) f(Cell{col, row});
    }
  }
}

}  // namespace rfbsim::sim
