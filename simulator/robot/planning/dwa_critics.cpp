// SPDX-License-Identifier: GPL-2.0-or-later
// DWA critics: obstacle clearance, distances to the path and goal, and oscillation suppression.
#include "robot/planning/dwa_critics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace rfbsim::sim {

namespace {

constexpr double kIllegal = -1.0;

// Angle a - b wrapped to (-pi, pi].
double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * std::numbers::pi); }

// Calls visit(cell) for each cell the straight segment a-b enters after a's own cell, in order (an exact
// grid traversal; through an exact corner both cells beside it too). Stops early when visit returns false.
template <typename Visit>
bool walk_segment(const CostmapGrid& grid, const Pose2& a, const Pose2& b, Visit&& visit) {
  const double x0 = (a.x - grid.origin_x) / grid.resolution;
  const double y0 = (a.y - grid.origin_y) / grid.resolution;
  const double x1 = (b.x - grid.origin_x) / grid.resolution;
  const double y1 = (b.y - grid.origin_y) / grid.resolution;
  Cell c{static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))};
  const Cell last{static_cast<int>(std::floor(x1)), static_cast<int>(std::floor(y1))};
  const double dx = x1 - x0;
  const double dy = y1 - y0;
  const int step_x = dx > 0.0 ? 1 : -1;
  const int step_y = dy > 0.0 ? 1 : -1;
  constexpr double kNever = std::numeric_limits<double>::infinity();
  // Parameter t (0..1 along the segment) of the next column and row boundary, and between boundaries.
  double next_x = dx == 0.0 ? kNever : (step_x > 0 ? c.col + 1 - x0 : x0 - c.col) / std::abs(dx);
  double next_y = dy == 0.0 ? kNever : (step_y > 0 ? c.row + 1 - y0 : y0 - c.row) / std::abs(dy);
  const double delta_x = dx == 0.0 ? kNever : 1.0 / std::abs(dx);
  const double delta_y = dy == 0.0 ? kNever : 1.0 / std::abs(dy);
  // Never more steps than the cells between the ends (a guard against rounding at the far boundary).
  for (int guard = std::abs(last.col - c.col) + std::abs(last.row - c.row); !(c == last) && guard > 0; --guard) {
    if (next_x < next_y) {
      c.col += step_x;
      next_x += delta_x;
    } else if (next_y < next_x) {
      c.row += step_y;
      next_y += delta_y;
    } else {
      if (!visit(Cell{c.col + step_x, c.row}) || !visit(Cell{c.col, c.row + step_y})) return false;
      c.col += step_x;
      c.row += step_y;
      next_x += delta_x;
      next_y += delta_y;
      --guard;
    }
    if (!visit(c)) return false;
  }
  return true;
}

}  // namespace

// ---- ObstacleCritic ----

bool ObstacleCritic::prepare(const DwaScene& scene) {
  grid_ = scene.grid;
  const std::uint8_t own = grid_->at_world(scene.pose.x, scene.pose.y);
  start_inscribed_ = own == cost::kInscribed;
  start_blocked_ = own > cost::kInscribed;
  return true;
}

double ObstacleCritic::score(const Rollout& rollout) const {
  if (start_blocked_ || rollout.poses.empty()) return kIllegal;
  // Every cell the rollout passes through, not only those its points fall in: chords between points a
  // sim_granularity apart stray from the arc by well under a millimetre, while points alone could step
  // over the corner of a cell the robot grazes. While the robot is still in the inscribed cells it started
  // among, those are allowed (and not scored); from the first cheaper cell on, every cell must stay below
  // inscribed.
  bool escaping = start_inscribed_;
  int max_cost = 0;
  const auto admit = [&](Cell c) {
    const std::uint8_t value = grid_->at(c, cost::kUnknown);
    if (escaping && value == cost::kInscribed) return true;
    escaping = false;
    if (value >= cost::kInscribed) return false;
    max_cost = std::max(max_cost, static_cast<int>(value));
    return true;
  };
  if (!admit(grid_->cell_of(rollout.poses[0].x, rollout.poses[0].y))) return kIllegal;
  for (std::size_t i = 1; i < rollout.poses.size(); ++i) {
    if (!walk_segment(*grid_, rollout.poses[i - 1], rollout.poses[i], admit)) return kIllegal;
    if (i == rollout.end && escaping) return kIllegal;  // still in inflation at sim_time
  }
  return max_cost;
}

// ---- MapDistanceCritic ----

bool MapDistanceCritic::prepare(const DwaScene& scene) {
  grid_ = scene.grid;
  map_ = target_ == Target::Path ? scene.path_map : target_ == Target::Goal ? scene.goal_map : scene.goal_front_map;
  if (!off_near_goal_) return true;
  const Eigen::Vector2d robot(scene.pose.x, scene.pose.y);
  // ROS: once close to the goal, keeping the nose on anything destabilises the approach.
  return (scene.local_goal - robot).squaredNorm() > shift_ * shift_;
}

double MapDistanceCritic::score(const Rollout& rollout) const {
  const Pose2& end = rollout.poses[rollout.end];
  const float at_end = map_->at(grid_->cell_of(end.x, end.y));
  if (!std::isfinite(at_end)) return kIllegal;
  if (shift_ == 0.0) return static_cast<double>(at_end);
  const float at_nose = map_->at(grid_->cell_of(end.x + shift_ * std::cos(end.yaw), end.y + shift_ * std::sin(end.yaw)));
  return std::isfinite(at_nose) ? static_cast<double>(at_nose) : static_cast<double>(at_end) + shift_;
}

// ---- OscillationCritic ----

double OscillationCritic::score(const Rollout& rollout) const {
  const bool reversal = (forward_only_ && rollout.v < 0.0) || (backward_only_ && rollout.v > 0.0) ||
                        (left_only_ && rollout.w < 0.0) || (right_only_ && rollout.w > 0.0);
  return reversal ? kIllegal : 0.0;
}

void OscillationCritic::update(const Pose2& pose, double v, double w) {
  // Driving: a change of direction forbids the old one.
  bool flagged = false;
  if (v < 0.0) {
    if (forward_) {
      backward_only_ = true;
      flagged = true;
    }
    forward_ = false;
    backward_ = true;
  }
  if (v > 0.0) {
    if (backward_) {
      forward_only_ = true;
      flagged = true;
    }
    backward_ = false;
    forward_ = true;
  }
  // Turning counts only when (nearly) in place, as in ROS.
  if (std::abs(v) <= min_vel_trans_) {
    if (w < 0.0) {
      if (left_) {
        right_only_ = true;
        flagged = true;
      }
      left_ = false;
      right_ = true;
    }
    if (w > 0.0) {
      if (right_) {
        left_only_ = true;
        flagged = true;
      }
      right_ = false;
      left_ = true;
    }
  }
  if (flagged) flagged_at_ = pose;
  // Moved or turned far enough since the last flag: everything is allowed again.
  if (forward_only_ || backward_only_ || left_only_ || right_only_) {
    const double moved = std::hypot(pose.x - flagged_at_.x, pose.y - flagged_at_.y);
    if (moved > reset_dist_ || std::abs(angle_diff(pose.yaw, flagged_at_.yaw)) > reset_angle_) reset();
  }
}

void OscillationCritic::reset() {
  forward_ = backward_ = forward_only_ = backward_only_ = false;
  left_ = right_ = left_only_ = right_only_ = false;
}

}  // namespace rfbsim::sim
