// SPDX-License-Identifier: GPL-2.0-or-later
// DwaPlanner: one control cycle (cut the path, build the distance maps, sample, roll out, score, choose)
// and the turn in place.
#include "robot/planning/dwa_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "robot/planning/grid_point.hpp"
#include "robot/planning/local_path.hpp"

namespace rfbsim::sim {

namespace {

}  // namespace

std::string dwa_params_error(const DwaParams& p) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  const auto non_negative = [](double x) { return std::isfinite(x) && x >= 0.0; };
  if (!std::isfinite(p.max_vel_x) || !std::isfinite(p.min_vel_x) || p.min_vel_x > p.max_vel_x) {
    return "bad DWA parameters: need finite min_vel_x <= max_vel_x";
  }
  if (!non_negative(p.max_vel_theta) || !non_negative(p.min_vel_theta) || !non_negative(p.min_vel_trans) ||
      !non_negative(p.acc_lim_x) || !non_negative(p.acc_lim_theta)) {
    return "bad DWA parameters: velocity limits and accelerations must be >= 0";
  }
  if (!positive(p.sim_time) || !positive(p.sim_granularity) || !positive(p.angular_sim_granularity) ||
      !positive(p.controller_frequency) || !non_negative(p.stop_time_buffer)) {
    return "bad DWA parameters: sim_time, granularities and controller_frequency must be > 0";
  }
  if (p.vx_samples < 1 || p.vth_samples < 1 || p.vx_samples > 1000 || p.vth_samples > 1000) {
    return "bad DWA parameters: vx_samples and vth_samples must be 1..1000";
  }
  if (!non_negative(p.path_distance_bias) || !non_negative(p.goal_distance_bias) || !non_negative(p.occdist_scale) ||
      !non_negative(p.forward_point_distance) || !non_negative(p.oscillation_reset_dist) ||
      !non_negative(p.oscillation_reset_angle) || !non_negative(p.people_clearance) ||
      !non_negative(p.people_horizon) || !non_negative(p.people_personal_clearance) ||
      !non_negative(p.people_walking_speed)) {
    return "bad DWA parameters: biases, scales, distances, people clearances, horizon and walking speed must be >= 0";
  }
  return {};
}

namespace {

// Deterministic preference among equal scores: faster, then straighter, then turning left.
bool preferred(double score, double v, double w, double best_score, double best_v, double best_w) {
  if (score != best_score) return score < best_score;
  if (v != best_v) return v > best_v;
  if (std::abs(w) != std::abs(best_w)) return std::abs(w) < std::abs(best_w);
  return w > best_w;
}

}  // namespace

DwaPlanner::DwaPlanner(DwaParams params)
    : params_(params),
      params_error_(dwa_params_error(params)),
      oscillation_(params.oscillation_reset_dist, params.oscillation_reset_angle, params.min_vel_trans),
      people_(params.robot_radius, params.people_clearance, params.people_horizon, params.sim_time,
              params.people_personal_clearance, params.people_walking_speed),
      path_("path_distance", MapDistanceCritic::Target::Path, 0.0, false),
      goal_("goal_distance", MapDistanceCritic::Target::Goal, 0.0, false),
      alignment_("alignment", MapDistanceCritic::Target::Path, params.forward_point_distance, true),
      goal_front_("goal_front", MapDistanceCritic::Target::GoalFront, params.forward_point_distance, false),
      // ROS's weights: the alignment shares the path's bias, the goal front the goal's.
      weights_{1.0, params.occdist_scale, 1.0, params.path_distance_bias, params.goal_distance_bias,
               params.path_distance_bias, params.goal_distance_bias} {}

void DwaPlanner::set_plan(std::vector<Eigen::Vector2d> global_path) {
  plan_error_.clear();
  for (const Eigen::Vector2d& p : global_path) {
    if (!p.allFinite()) {
      plan_error_ = "the global path has a non-finite point";
      global_path.clear();
      break;
    }
  }
  plan_ = std::move(global_path);
  progress_ = 0;
  oscillation_.reset();
}

DwaCommand DwaPlanner::fail(std::string reason) const {
  DwaCommand command;
  command.reason = std::move(reason);
  return command;
}

const DistanceGrid* DwaPlanner::build_maps(const CostmapGrid& local, const Eigen::Vector2d& robot) {
  path_map_.compute(local, path_cells_);
  // The goal map grows from the local goal's cell; if an obstacle covers it (a person on the path at the
  // window's edge), from the last free path cell before it, so that the goal stays reachable (ROS would
  // reject every rollout).
  std::size_t goal_at = path_cells_.size() - 1;
  while (goal_at > 0 && local.costs[static_cast<std::size_t>(path_cells_[goal_at])] >= cost::kInscribed) --goal_at;
  goal_cells_.assign(1, path_cells_[goal_at]);
  goal_map_.compute(local, goal_cells_);
  // The goal front: the local goal pushed one nose length on, away from the robot, so that the nose is drawn
  // to it. It stops short where the way on leaves the window or meets an obstacle (a goal in front of a
  // wall), as ROS's stops at the window's edge; with no room at all the goal map serves.
  const DistanceGrid* front_map = &goal_map_;
  const Eigen::Vector2d to_goal = local_goal_ - robot;
  const Cell goal_cell = local.cell_of(local_goal_.x(), local_goal_.y());
  if (to_goal.norm() > 1e-9 && local.at(goal_cell) < cost::kInscribed) {
    const Eigen::Vector2d direction = to_goal.normalized();
    const double step = 0.5 * local.resolution;
    Cell front_cell = goal_cell;
    for (double along = step; along < params_.forward_point_distance + 0.5 * step; along += step) {
      const Eigen::Vector2d front = local_goal_ + std::min(along, params_.forward_point_distance) * direction;
      const Cell c = local.cell_of(front.x(), front.y());
      if (!local.in_bounds(c) || local.at(c) >= cost::kInscribed) break;
      front_cell = c;
    }
    if (!(front_cell == goal_cell)) {
      goal_cells_.assign(1, static_cast<std::int32_t>(local.index(front_cell)));
      goal_front_map_.compute(local, goal_cells_);
      front_map = &goal_front_map_;
    }
  }
  return front_map;
}

std::string DwaPlanner::rejection_reason(int rollouts, const std::array<int, kCritics>& rejected) {
  if (rollouts == 0) return "no velocity sample in the dynamic window moves the robot";
  const std::array<DwaCritic*, kCritics> critic_list = critics();
  for (std::size_t k = 0; k < kCritics; ++k) {
    if (rejected[k] == rollouts) return "all " + std::to_string(rollouts) + " rollouts " + critic_list[k]->rejection();
  }
  std::string reason = "no legal rollout among " + std::to_string(rollouts) + ":";
  const char* separator = " ";
  for (std::size_t k = 0; k < kCritics; ++k) {
    if (rejected[k] == 0) continue;
    reason += separator + std::to_string(rejected[k]) + " " + critic_list[k]->rejection();
    separator = ", ";
  }
  return reason;
}

DwaCommand DwaPlanner::compute(const CostmapGrid& local, const Pose2& pose, double v, double w) {
  // Inputs: everything below relies on them.
  if (!params_error_.empty()) return fail(params_error_);
  if (!plan_error_.empty()) return fail(plan_error_);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.yaw)) return fail("the robot's pose is not finite");
  if (!std::isfinite(v) || !std::isfinite(w)) return fail("the robot's velocity is not finite");
  if (local.width <= 0 || local.height <= 0 || !(local.resolution > 0.0) ||
      local.costs.size() != static_cast<std::size_t>(local.width) * static_cast<std::size_t>(local.height)) {
    return fail("the local costmap is empty or its cost array does not match its size");
  }
  const Eigen::Vector2d robot(pose.x, pose.y);
  if (!on_grid(local, pose.x, pose.y)) {
    char text[96];
    std::snprintf(text, sizeof text, "the robot (%.2f, %.2f) is off the local costmap", pose.x, pose.y);
    return fail(text);
  }

  // The stretch of the global path on this window, and the distance maps the critics read: to the path,
  // to the local goal, and to the local goal pushed one nose length further (ROS's goal front).
  const double horizon = std::hypot(local.width, local.height) * local.resolution;
  const LocalPathCut cut = cut_local_path(plan_, progress_, horizon, local, robot, path_cells_);
  if (!cut.ok) return fail(cut.reason);
  progress_ = cut.nearest;
  local_goal_ = cut.local_goal;
  const DistanceGrid* front_map = build_maps(local, robot);
  const DwaScene scene{&local, pose, local_goal_, &path_map_, &goal_map_, front_map};
  const std::array<DwaCritic*, kCritics> critic_list = critics();
  std::array<bool, kCritics> active{};
  for (std::size_t k = 0; k < kCritics; ++k) active[k] = critic_list[k]->prepare(scene);

  // Sample the window; score each rollout critic by critic, stopping as soon as one rejects it or its
  // running cost already exceeds the best complete one (so ties are always scored in full).
  const VelocityWindow window = dynamic_window(params_, v, w);
  velocity_samples(window.v_min, window.v_max, params_.vx_samples, v_samples_);
  velocity_samples(window.w_min, window.w_max, params_.vth_samples, w_samples_);
  std::array<int, kCritics> rejected{};
  int rollouts = 0;
  bool have_best = false;
  double best_score = 0.0;
  const auto consider = [&](double sv, double sw) {
    // ROS's dead band: too slow both to drive and to turn.
    constexpr double kEps = 1e-4;
    if (std::abs(sv) + kEps < params_.min_vel_trans && std::abs(sw) + kEps < params_.min_vel_theta) return;
    if (!roll_out(pose, sv, sw, params_, candidate_)) return;
    ++rollouts;
    double total = 0.0;
    for (std::size_t k = 0; k < kCritics; ++k) {
      if (!active[k]) continue;
      const double cost = critic_list[k]->score(candidate_);
      if (cost < 0.0) {
        ++rejected[k];
        return;
      }
      total += weights_[k] * cost;
      if (have_best && total > best_score) return;
    }
    if (!have_best || preferred(total, sv, sw, best_score, best_.v, best_.w)) {
      std::swap(best_, candidate_);
      best_score = total;
      have_best = true;
    }
  };
  for (const double sv : v_samples_) {
    for (const double sw : w_samples_) consider(sv, sw);
  }
  // rfbsim: one more sample, braking as hard as allowed along the current arc (same curvature). If last
  // cycle's command was clear for sim_time, this one stays on that checked arc and is clear too, so a robot
  // moving too fast to stop within one period is never left with no legal command by its own dynamics.
  if (v > 0.0 && window.v_min > 0.0 && window.v_min < v) {
    const double brake_w = w * window.v_min / v;
    const bool sampled = std::find(w_samples_.begin(), w_samples_.end(), brake_w) != w_samples_.end();
    if (brake_w >= window.w_min && brake_w <= window.w_max && !sampled) consider(window.v_min, brake_w);
  }

  if (!have_best) {
    DwaCommand command = fail(rejection_reason(rollouts, rejected));
    command.rollouts = rollouts;
    return command;
  }

  DwaCommand command;
  command.found = true;
  command.v = best_.v;
  command.w = best_.w;
  command.score = best_score;
  command.rollouts = rollouts;
  command.trajectory.reserve(best_.end + 1);
  for (std::size_t i = 0; i <= best_.end; ++i) command.trajectory.emplace_back(best_.poses[i].x, best_.poses[i].y);
  oscillation_.update(pose, command.v, command.w);
  return command;
}

DwaCommand DwaPlanner::rotate_toward(const CostmapGrid& local, const Pose2& pose, double w, double target_yaw) const {
  if (!params_error_.empty()) return fail(params_error_);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.yaw) || !std::isfinite(w) ||
      !std::isfinite(target_yaw)) {
    return fail("the robot's pose, turn rate or target heading is not finite");
  }
  if (local.costs.size() != static_cast<std::size_t>(std::max(0, local.width)) * static_cast<std::size_t>(std::max(0, local.height))) {
    return fail("the local costmap's cost array does not match its size");
  }
  const std::uint8_t own = on_grid(local, pose.x, pose.y) ? local.at_world(pose.x, pose.y) : cost::kUnknown;
  if (own > cost::kInscribed) {
    return fail("cannot turn in place: the robot's cell is " +
                std::string(own == cost::kLethal ? "lethal" : "unknown or off the local costmap"));
  }
  // The fastest turn that can still stop on the heading, braking by d = acc_lim_theta dt each period from
  // the next one on: commanding w with k more periods of braking after it (k d <= w < (k + 1) d) turns
  // dt ((k + 1) w - d k (k + 1) / 2); the largest w for which that stays within the error e, found for the
  // smallest k that fits. With k = 0 this is e / dt: never past the heading within one period.
  const double error = std::remainder(target_yaw - pose.yaw, 2.0 * std::numbers::pi);
  const double dt = 1.0 / params_.controller_frequency;
  const double brake = params_.acc_lim_theta * dt;
  double stoppable = params_.max_vel_theta;
  for (int k = 0; brake > 0.0 && k * brake < params_.max_vel_theta; ++k) {
    const double candidate = (std::abs(error) / dt + 0.5 * brake * k * (k + 1)) / (k + 1);
    if (candidate < (k + 1) * brake) {
      stoppable = candidate;
      break;
    }
  }
  double speed = std::min(params_.max_vel_theta, stoppable);
  if (speed > 0.0) speed = std::max(speed, std::min(params_.min_vel_theta, params_.max_vel_theta));
  const double wanted = std::copysign(speed, error);
  DwaCommand command;
  command.found = true;
  command.v = 0.0;
  command.w = std::clamp(std::clamp(wanted, w - brake, w + brake), -params_.max_vel_theta, params_.max_vel_theta);
  command.trajectory = {Eigen::Vector2d(pose.x, pose.y)};
  return command;
}

bool within_xy_tolerance(const Pose2& pose, const Eigen::Vector2d& goal, double xy_goal_tolerance) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !goal.allFinite() || !std::isfinite(xy_goal_tolerance)) {
    return false;
  }
  return std::hypot(pose.x - goal.x(), pose.y - goal.y()) <= xy_goal_tolerance;
}

}  // namespace rfbsim::sim
