// SPDX-License-Identifier: GPL-2.0-or-later
// TaskMonitor: step progress, the clock and the outcome.
#include "task/task_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rfbsim::sim {

namespace {

double wrapped(double angle) { return std::remainder(angle, 2.0 * std::numbers::pi); }

double avatar_distance_to(const World& world, double x, double y) {
  return std::hypot(world.avatar.pose.x - x, world.avatar.pose.y - y);
}

}  // namespace

const char* task_outcome_name(TaskOutcome outcome) {
  switch (outcome) {
    case TaskOutcome::Completed: return "completed";
    case TaskOutcome::Timeout: return "timeout";
    case TaskOutcome::None: break;
  }
  return "none";
}

bool robot_in_view(const World& world, double range, double half_angle) {
  if (!world.robot) return false;
  const Pose2& me = world.avatar.pose;
  const double dx = world.robot->pose.x - me.x;
  const double dy = world.robot->pose.y - me.y;
  const double distance = std::hypot(dx, dy);
  if (distance > range) return false;
  if (distance < 1e-9) return true;
  const double bearing = std::atan2(dy, dx);
  if (std::abs(wrapped(bearing - me.yaw)) > half_angle) return false;
  // Sight ends at the robot's body: a wall behind it does not hide it.
  const double to_body = std::max(0.0, distance - world.robot->radius);
  return world.obstacles.ray_cast(me.x, me.y, bearing, to_body) >= to_body - 1e-9;
}

TaskMonitor::TaskMonitor(TaskSpec spec, double dt) : spec_(std::move(spec)), dt_(dt) {}

void TaskMonitor::start_timer(const World& world) {
  if (!active() || start_tick_) return;
  start_tick_ = world.tick;
  last_tick_ = world.tick;
  events_.push_back({TaskEvent::Kind::TimerStarted, world.tick});
  last_walked_ = world.avatar.distance_walked;
  last_yaw_ = world.avatar.pose.yaw;
  last_camera_ = world.camera.height;
  step_ = 0;
  begin_step(world.tick);
}

void TaskMonitor::begin_step(std::uint64_t tick) {
  amount_ = 0.0;
  events_.push_back({TaskEvent::Kind::StepStarted, tick, step_});
}

void TaskMonitor::observe(const World& world) {
  if (!start_tick_ || outcome_ != TaskOutcome::None) return;
  last_tick_ = world.tick;
  if (advance(world)) {
    events_.push_back({TaskEvent::Kind::StepDone, world.tick, step_});
    ++step_;
    if (step_ == static_cast<int>(spec_.steps.size())) {
      finish(TaskOutcome::Completed, world.tick);
      return;
    }
    begin_step(world.tick);
  }
  // Done and out of time at the same tick counts as done: the participant got there.
  if (static_cast<double>(world.tick - *start_tick_) * dt_ >= spec_.time_limit - 1e-9) {
    finish(TaskOutcome::Timeout, world.tick);
  }
}

bool TaskMonitor::advance(const World& world) {
  const TaskStep& step = spec_.steps[static_cast<std::size_t>(step_)];
  // The change since the last tick, taken every tick whatever the step, so that a step counts only what
  // the participant did while it was the current one.
  const double walked = std::abs(world.avatar.distance_walked - last_walked_);
  const double turned = std::abs(wrapped(world.avatar.pose.yaw - last_yaw_));
  const double climbed = std::abs(world.camera.height - last_camera_);
  last_walked_ = world.avatar.distance_walked;
  last_yaw_ = world.avatar.pose.yaw;
  last_camera_ = world.camera.height;
  switch (step.type) {
    case TaskType::Walk:
      amount_ += walked;
      return amount_ >= step.distance;
    case TaskType::Turn:
      amount_ += turned;
      return amount_ >= step.angle;
    case TaskType::Camera:
      amount_ += climbed;
      return amount_ >= step.distance;
    case TaskType::FindRobot:
      return robot_in_view(world, step.distance, step.view_angle);
    case TaskType::FollowRobot:
      if (world.robot && avatar_distance_to(world, world.robot->pose.x, world.robot->pose.y) <= step.distance) {
        amount_ += dt_;
      }
      return amount_ >= step.duration - 1e-9;
    case TaskType::Reach:
      return step.target && avatar_distance_to(world, step.target->x(), step.target->y()) <= step.distance;
  }
  return false;
}

void TaskMonitor::finish(TaskOutcome outcome, std::uint64_t tick) {
  outcome_ = outcome;
  outcome_tick_ = tick;
  events_.push_back({TaskEvent::Kind::Outcome, tick, step_, outcome});
}

TaskStatus TaskMonitor::status() const {
  TaskStatus status;
  status.timer_running = start_tick_.has_value() && outcome_ == TaskOutcome::None;
  status.step = step_;
  status.amount = amount_;
  status.outcome = outcome_;
  const double elapsed = start_tick_ ? static_cast<double>(last_tick_ - *start_tick_) * dt_ : 0.0;
  status.time_left = std::max(0.0, spec_.time_limit - elapsed);
  if (step_ >= 0 && step_ < static_cast<int>(spec_.steps.size())) {
    const TaskStep& step = spec_.steps[static_cast<std::size_t>(step_)];
    switch (step.type) {
      case TaskType::Walk:
      case TaskType::Camera: status.goal = step.distance; break;
      case TaskType::Turn: status.goal = step.angle; break;
      case TaskType::FollowRobot: status.goal = step.duration; break;
      case TaskType::FindRobot:
      case TaskType::Reach: status.goal = 0.0; break;
    }
  }
  return status;
}

}  // namespace rfbsim::sim
