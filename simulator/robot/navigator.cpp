// SPDX-License-Identifier: GPL-2.0-or-later
// Navigator: move_base's cycle (plan, control, goal check) and its recovery behaviours.
#include "robot/navigator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

namespace rfbsim::sim {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// `value` with `decimals` digits after the point (0..3).
std::string fixed(double value, int decimals = 2) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

/// "(x, y)" in metres with centimetres.
std::string point(double x, double y) { return "(" + fixed(x) + ", " + fixed(y) + ")"; }

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double angle_between(double a, double b) { return std::remainder(a - b, kTwoPi); }

double path_length(const std::vector<Eigen::Vector2d>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

}  // namespace

Navigator::Navigator(NavigatorParams params, GlobalPlannerParams planner, DwaParams dwa)
    : params_(params), planner_(planner), dwa_(dwa) {}

std::optional<std::string> Navigator::set_goal(const Pose2& goal, const GridMap& map, double radius) {
  path_.clear();
  trajectory_.clear();
  goal_.reset();
  std::string refusal;
  if (!std::isfinite(goal.x) || !std::isfinite(goal.y) || !std::isfinite(goal.yaw)) {
    refusal = "goal refused: its pose is not a number";
  } else if (!map.contains(goal.x, goal.y)) {
    refusal = "goal refused: " + point(goal.x, goal.y) + " is off the map";
  } else if (map.disc_hits_wall(goal.x, goal.y, radius)) {
    refusal = "goal refused: " + point(goal.x, goal.y) + " is inside a wall or prop (the robot's " + fixed(radius) +
              " m footprint would overlap it)";
  }
  if (!refusal.empty()) {
    enter(RobotState::Failed, refusal);
    return refusal;
  }
  goal_ = goal;
  fresh_goal_ = true;
  replan_now_ = true;
  recovery_index_ = 0;
  enter(RobotState::Planning, "goal " + point(goal.x, goal.y));
  return std::nullopt;
}

void Navigator::cancel() {
  goal_.reset();
  path_.clear();
  trajectory_.clear();
  enter(RobotState::Idle, "goal cancelled");
}

NavCommand Navigator::cycle(double now, const Pose2& pose, double v, double w, const CostmapGrid& global,
                            const CostmapGrid& local, std::optional<Eigen::Vector2d> goal_person) {
  if (!goal_ || state_ == RobotState::Idle || state_ == RobotState::Arrived || state_ == RobotState::Failed) {
    trajectory_.clear();
    return {};
  }
  if (fresh_goal_) {
    // The patience timers start with the goal.
    fresh_goal_ = false;
    last_valid_plan_ = last_valid_control_ = last_progress_ = now;
    progress_anchor_ = {pose.x, pose.y};
  }
  if (state_ == RobotState::Recovering) return recover(now, pose, w, local);
  track_progress(now, pose);

  // Goal check first: within tolerance (and facing the goal's heading, when it has one), or at social
  // distance from the person standing at it.
  const Eigen::Vector2d to_goal(goal_->x - pose.x, goal_->y - pose.y);
  const double distance = to_goal.norm();
  if (goal_reached(pose, goal_person)) {
    path_.clear();
    trajectory_.clear();
    const double from_person = goal_person ? (*goal_person - Eigen::Vector2d(pose.x, pose.y)).norm() : 0.0;
    enter(RobotState::Arrived, goal_person && from_person <= params_.person_goal_distance
                                   ? fixed(from_person) + " m from the person at the goal"
                                   : fixed(distance) + " m from the goal");
    return {};
  }
  // Not getting anywhere (dithering, waiting behind someone who does not move, or failing to face the
  // goal's heading): recover.
  if (params_.oscillation_timeout > 0.0 && now - last_progress_ > params_.oscillation_timeout) {
    start_recovery(now, pose, "moved less than " + fixed(params_.oscillation_distance) + " m in " +
                                  fixed(params_.oscillation_timeout, 0) + " s");
    return state_ == RobotState::Recovering ? recover(now, pose, w, local) : NavCommand{};
  }
  if (distance <= params_.xy_goal_tolerance) {
    // In place but facing the wrong way: turn to the goal's heading.
    const DwaCommand turn = dwa_.rotate_toward(local, pose, w, goal_->yaw);
    trajectory_.clear();
    return {0.0, turn.found ? turn.w : 0.0, std::nullopt};
  }

  // Global plan: when due, and at once after the local planner found nothing legal (move_base goes back to
  // planning then). A failed replan keeps following the last plan until planner_patience runs out.
  const bool due = params_.planner_frequency > 0.0 && now - last_plan_time_ >= 1.0 / params_.planner_frequency;
  if (replan_now_ || due || path_.empty()) {
    if (!replan(now, pose, global) &&
        now - last_valid_plan_ > params_.planner_patience) {
      start_recovery(now, pose, "no global plan for " + fixed(now - last_valid_plan_, 1) + " s: " + plan_failure_);
      return state_ == RobotState::Recovering ? recover(now, pose, w, local) : NavCommand{};
    }
    if (path_.empty()) return {};
  }

  // The way on lies behind or beside the robot: turn toward it in place first.
  if (const auto bearing = path_bearing(pose)) {
    const double error = angle_between(*bearing, pose.yaw);
    if (std::abs(error) > params_.rotate_to_path_angle) {
      const DwaCommand turn = dwa_.rotate_toward(local, pose, w, *bearing);
      if (turn.found) {
        last_valid_control_ = now;
        trajectory_.clear();
        return {0.0, turn.w, std::nullopt};
      }
    }
  }

  // Local plan: a legal velocity, or stop and wait (yield) until controller_patience runs out.
  const auto started = std::chrono::steady_clock::now();
  const DwaCommand command = dwa_.compute(local, pose, v, w);
  times_.control_seconds += seconds_since(started);
  ++times_.controls;
  if (command.found) {
    last_valid_control_ = now;
    trajectory_ = command.trajectory;
    return {command.v, command.w, std::nullopt};
  }
  // Yield: stop, and replan soon on the fresher costmap (move_base replans at once; at most twice a second
  // here, as an A* over the warehouse costs up to a few ms).
  trajectory_.clear();
  replan_now_ = now - last_plan_time_ >= 0.5;
  if (now - last_valid_control_ > params_.controller_patience) {
    start_recovery(now, pose, "no legal velocity for " + fixed(now - last_valid_control_, 1) + " s: " + command.reason);
    return state_ == RobotState::Recovering ? recover(now, pose, w, local) : NavCommand{};
  }
  return {};
}

std::optional<Eigen::Vector2d> point_ahead(const std::vector<Eigen::Vector2d>& path, const Eigen::Vector2d& from,
                                           double distance) {
  if (path.size() < 2) return std::nullopt;
  std::size_t nearest = 0;
  double best = 1e18;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double d = (path[i] - from).squaredNorm();
    if (d < best) {
      best = d;
      nearest = i;
    }
  }
  for (std::size_t i = nearest + 1; i < path.size(); ++i) {
    if ((path[i] - from).norm() >= distance || i + 1 == path.size()) return path[i];
  }
  return std::nullopt;
}

std::optional<double> Navigator::path_bearing(const Pose2& pose) const {
  const auto ahead = point_ahead(path_, {pose.x, pose.y}, params_.rotate_lookahead);
  if (!ahead) return std::nullopt;
  return std::atan2(ahead->y() - pose.y, ahead->x() - pose.x);
}

bool Navigator::goal_reached(const Pose2& pose, const std::optional<Eigen::Vector2d>& goal_person) const {
  const double distance = std::hypot(goal_->x - pose.x, goal_->y - pose.y);
  const bool heading_free = params_.yaw_goal_tolerance >= std::numbers::pi;
  if (distance <= params_.xy_goal_tolerance &&
      (heading_free || std::abs(angle_between(pose.yaw, goal_->yaw)) <= params_.yaw_goal_tolerance)) {
    return true;
  }
  // The goal is a person: social distance from them is arrived (whatever the heading: they are the goal).
  return goal_person && (*goal_person - Eigen::Vector2d(pose.x, pose.y)).norm() <= params_.person_goal_distance;
}

std::optional<Eigen::Vector2d> goal_person_at(const Pose2& goal, std::span<const SeenPerson> people,
                                              const NavigatorParams& params) {
  std::optional<Eigen::Vector2d> found;
  double nearest = params.person_goal_distance;
  for (const SeenPerson& person : people) {
    if (!person.position.allFinite() || !(person.velocity.norm() < params.person_goal_standing_speed)) continue;
    const double d = (person.position - Eigen::Vector2d(goal.x, goal.y)).norm();
    if (d <= nearest) {
      nearest = d;
      found = person.position;
    }
  }
  return found;
}

bool Navigator::replan(double now, const Pose2& pose, const CostmapGrid& global) {
  last_plan_time_ = now;
  replan_now_ = false;
  const auto started = std::chrono::steady_clock::now();
  GlobalPlan plan = planner_.plan(global, {pose.x, pose.y}, {goal_->x, goal_->y});
  times_.plan_seconds += seconds_since(started);
  ++times_.plans;
  if (!plan.ok) {
    plan_failure_ = plan.reason;
    return false;
  }
  path_ = std::move(plan.path);
  dwa_.set_plan(path_);
  last_valid_plan_ = now;
  if (state_ == RobotState::Planning) enter(RobotState::Moving, "following a " + fixed(path_length(path_), 1) + " m path");
  return true;
}

void Navigator::track_progress(double now, const Pose2& pose) {
  const Eigen::Vector2d at(pose.x, pose.y);
  if ((at - progress_anchor_).norm() >= params_.oscillation_distance) {
    // Real progress: the patience with being stuck, and the recovery ladder, start over.
    progress_anchor_ = at;
    last_progress_ = now;
    recovery_index_ = 0;
  }
}

void Navigator::start_recovery(double now, const Pose2& pose, std::string trigger) {
  recovery_started_ = now;
  if (!params_.recovery_behavior_enabled || recovery_index_ >= kRecoverySteps) {
    path_.clear();
    trajectory_.clear();
    enter(RobotState::Failed, "gave up: " + trigger);
    return;
  }
  recovery_trigger_ = std::move(trigger);
  rotated_ = 0.0;
  last_yaw_ = pose.yaw;
  trajectory_.clear();
  static constexpr const char* kNames[kRecoverySteps] = {"clearing distant obstacles", "rotating in place",
                                                         "clearing nearby obstacles", "rotating in place"};
  enter(RobotState::Recovering, std::string(kNames[recovery_index_]) + " (" + recovery_trigger_ + ")");
}

NavCommand Navigator::recover(double now, const Pose2& pose, double w, const CostmapGrid& local) {
  const auto finish = [&] {
    ++recovery_index_;
    replan_now_ = true;
    last_valid_plan_ = last_valid_control_ = last_progress_ = now;
    progress_anchor_ = {pose.x, pose.y};
    enter(RobotState::Planning, "after recovery");
  };
  switch (recovery_index_) {
    case 0:
    case 2: {
      const double distance = recovery_index_ == 0 ? params_.conservative_reset_dist : params_.aggressive_reset_dist;
      finish();
      return {0.0, 0.0, distance};
    }
    default: {
      // Rotate a full turn so the lidar sees all round, unless the costmap says turning would hit something.
      rotated_ += std::abs(angle_between(pose.yaw, last_yaw_));
      last_yaw_ = pose.yaw;
      // A full turn, or as long as a full turn should take (with margin) if the base cannot turn so far.
      const double turn_time = kTwoPi / std::max(dwa_.params().max_vel_theta, 0.1) * 1.5 + 2.0;
      if (rotated_ >= kTwoPi - 0.1 || now - recovery_started_ > turn_time) {
        finish();
        return {};
      }
      const DwaCommand turn = dwa_.rotate_toward(local, pose, w, pose.yaw + std::numbers::pi / 2.0);
      if (!turn.found) {
        finish();
        return {};
      }
      return {0.0, turn.w, std::nullopt};
    }
  }
}

void Navigator::enter(RobotState state, std::string detail) {
  const bool changed = state != state_;
  state_ = state;
  detail_ = std::move(detail);
  if (changed || state == RobotState::Recovering || state == RobotState::Failed) events_.push_back({state_, detail_});
}

std::vector<NavEvent> Navigator::take_events() { return std::exchange(events_, {}); }

}  // namespace rfbsim::sim
