// SPDX-License-Identifier: GPL-2.0-or-later
// ObstacleLayer: raytracing (an exact grid walk), marking, footprint and recovery clearing.
#include "robot/costmap/obstacle_layer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rfbsim::sim {

namespace {

bool finite(const Pose2& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.yaw); }

}  // namespace

ObstacleLayer::ObstacleLayer(const ObstacleLayerParams& params, const CostmapGrid& frame, double footprint_radius)
    : params_(params),
      footprint_radius_(footprint_radius),
      marks_(CostmapGrid::sized(frame.width, frame.height, frame.resolution, frame.origin_x, frame.origin_y)) {}

bool ObstacleLayer::add_scan(const Pose2& pose, const LaserScan& scan) {
  if (!finite(pose) || !std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment)) return false;
  const double res = marks_.resolution;
  // The sensor in frame cell units. A sensor so far off the frame that no beam reaches it changes
  // nothing (and keeps the cell indices below within int).
  const double x = (pose.x - marks_.origin_x) / res;
  const double y = (pose.y - marks_.origin_y) / res;
  const double reach = std::max(params_.obstacle_range, params_.raytrace_range) / res + 2.0;
  if (x < -reach || y < -reach || x > marks_.width + reach || y > marks_.height + reach) return true;

  // A beam with no return clears as far as the lidar could have seen, at most raytrace_range (a NaN
  // range_max fails the comparison and leaves raytrace_range).
  double no_return_length = params_.raytrace_range;
  if (scan.range_max < no_return_length) no_return_length = scan.range_max;

  // First every beam clears, then every return marks (costmap_2d's order), so that a beam passing through
  // the cell another beam of the same scan hit does not erase that hit.
  hits_.clear();
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double r = scan.ranges[i];
    if (!(r >= scan.range_min) || r < 0.0) continue;  // too near to trust, negative, or NaN
    const double angle = pose.yaw + scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    const double dx = std::cos(angle);
    const double dy = std::sin(angle);
    const bool hit = r < scan.range_max;  // range_max (or inf) means nothing was hit
    if (hit && r <= params_.raytrace_range) {
      clear_ray(x, y, dx, dy, r / res, true);
    } else {
      clear_ray(x, y, dx, dy, (hit ? params_.raytrace_range : no_return_length) / res, false);
    }
    if (hit && r <= params_.obstacle_range) {
      hits_.push_back({static_cast<int>(std::floor(x + dx * r / res)),
                       static_cast<int>(std::floor(y + dy * r / res))});
    }
  }
  for (const Cell& c : hits_) mark(c);
  return true;
}

void ObstacleLayer::clear_ray(double x, double y, double dx, double dy, double length, bool keep_last) {
  if (!(length > 0.0)) return;
  // Amanatides-Woo: visit every cell the segment crosses, in order, by the ray parameter t (cells).
  int col = static_cast<int>(std::floor(x));
  int row = static_cast<int>(std::floor(y));
  const int step_col = dx > 0 ? 1 : -1;
  const int step_row = dy > 0 ? 1 : -1;
  constexpr double kNever = std::numeric_limits<double>::infinity();
  const double delta_col = dx != 0.0 ? std::abs(1.0 / dx) : kNever;
  const double delta_row = dy != 0.0 ? std::abs(1.0 / dy) : kNever;
  double next_col = dx > 0 ? (col + 1 - x) * delta_col : dx < 0 ? (x - col) * delta_col : kNever;
  double next_row = dy > 0 ? (row + 1 - y) * delta_row : dy < 0 ? (y - row) * delta_row : kNever;

  // The usual case: both ends a cell or more inside the frame, so every cell between is too (the last
  // cell may be a neighbour of the end point's by rounding). Walk flat indices without bounds checks and
  // without a hard-to-predict branch per step.
  const auto inside = [this](double px, double py) {
    return px >= 1.0 && py >= 1.0 && px < marks_.width - 1.0 && py < marks_.height - 1.0;
  };
  if (inside(x, y) && inside(x + dx * length, y + dy * length)) {
    std::uint8_t* cells = marks_.costs.data();
    std::ptrdiff_t index = static_cast<std::ptrdiff_t>(row) * marks_.width + col;
    const std::ptrdiff_t col_stride = step_col;
    const std::ptrdiff_t row_stride = static_cast<std::ptrdiff_t>(step_row) * marks_.width;
    for (;;) {
      const bool along_col = next_col < next_row;
      const bool last = (along_col ? next_col : next_row) >= length;  // the end point lies in this cell
      if (cells[index] != cost::kFree && (!last || !keep_last)) {
        clear({static_cast<int>(index % marks_.width), static_cast<int>(index / marks_.width)});
      }
      if (last) return;
      index += along_col ? col_stride : row_stride;
      next_col += along_col ? delta_col : 0.0;
      next_row += along_col ? 0.0 : delta_row;
    }
  }

  // Near or beyond the frame's edge: check every cell.
  const bool started_inside = marks_.in_bounds({col, row});
  for (;;) {
    const bool last = std::min(next_col, next_row) >= length;
    if (marks_.in_bounds({col, row})) {
      if (!last || !keep_last) clear({col, row});
    } else if (started_inside) {
      return;  // left the frame, and a straight ray never comes back
    }
    if (last) return;
    if (next_col < next_row) {
      next_col += delta_col;
      col += step_col;
    } else {
      next_row += delta_row;
      row += step_row;
    }
  }
}

void ObstacleLayer::mark(Cell c) {
  if (!marks_.in_bounds(c)) return;
  std::uint8_t& m = marks_.costs[marks_.index(c)];
  if (m != cost::kFree) return;
  m = cost::kLethal;
  ++mark_count_;
  changed_.include(c);
  marked_.include(c);
}

void ObstacleLayer::clear_footprint(double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y) || mark_count_ == 0) return;
  const double res = marks_.resolution;
  const double r = footprint_radius_;
  // Cell indices clamped in floating point first, so that a far-off robot cannot overflow them.
  const auto index = [res](double v, double origin, int size) {
    return static_cast<int>(std::floor(std::clamp((v - origin) / res, -2.0, size + 1.0)));
  };
  const CellWindow box = CellWindow{index(x - r, marks_.origin_x, marks_.width),
                                    index(y - r, marks_.origin_y, marks_.height),
                                    index(x + r, marks_.origin_x, marks_.width),
                                    index(y + r, marks_.origin_y, marks_.height)}
                             .clipped(marks_.width, marks_.height);
  for (int row = box.min_row; row <= box.max_row; ++row) {
    for (int col = box.min_col; col <= box.max_col; ++col) {
      if ((marks_.cell_centre({col, row}) - Eigen::Vector2d(x, y)).squaredNorm() <= r * r) clear({col, row});
    }
  }
  clear({index(x, marks_.origin_x, marks_.width), index(y, marks_.origin_y, marks_.height)});
}

int ObstacleLayer::clear_beyond(const Eigen::Vector2d& centre, double distance) {
  if (!centre.allFinite() || std::isnan(distance)) return 0;
  int dropped = 0;
  const double limit = distance < 0.0 ? -1.0 : distance * distance;  // below 0: everything is farther
  for_each_mark(marked_, [&](Cell c) {
    if ((marks_.cell_centre(c) - centre).squaredNorm() > limit) {
      clear(c);
      ++dropped;
    }
  });
  if (mark_count_ == 0) marked_ = CellWindow::none();
  return dropped;
}

void ObstacleLayer::clear_all() {
  const CellWindow w = marked_.clipped(marks_.width, marks_.height);
  for (int row = w.min_row; row <= w.max_row; ++row) {
    std::uint8_t* cells = &marks_.costs[marks_.index({w.min_col, row})];
    std::fill(cells, cells + w.columns(), cost::kFree);
  }
  if (mark_count_ > 0) changed_.include(w);
  marked_ = CellWindow::none();
  mark_count_ = 0;
}

void ObstacleLayer::update_bounds(CellWindow& frame_bounds) {
  frame_bounds.include(changed_);
  changed_ = CellWindow::none();
}

void ObstacleLayer::update_costs(CostmapGrid& master, const CellWindow& window, FrameOffset offset) const {
  for_each_mark(window.shifted(offset.col, offset.row), [&](Cell c) {
    master.costs[master.index({c.col - offset.col, c.row - offset.row})] = cost::kLethal;
  });
}

}  // namespace rfbsim::sim
