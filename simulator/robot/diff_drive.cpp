// SPDX-License-Identifier: GPL-2.0-or-later
// DiffDrive: commands ramped within the base's limits.
#include "robot/diff_drive.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::sim {

namespace {

double approach(double from, double to, double max_change) {
  return from + std::clamp(to - from, -max_change, max_change);
}

}  // namespace

WheelSpeeds wheel_speeds(const DriveLimits& limits, double v, double w) {
  const double half_track = 0.5 * limits.wheel_separation;
  return {(v - w * half_track) / limits.wheel_radius, (v + w * half_track) / limits.wheel_radius};
}

void DiffDrive::command(double v, double w) {
  wanted_v_ = std::isfinite(v) ? std::clamp(v, limits_.min_vel_x, limits_.max_vel_x) : 0.0;
  wanted_w_ = std::isfinite(w) ? std::clamp(w, -limits_.max_vel_theta, limits_.max_vel_theta) : 0.0;
}

void DiffDrive::step(double dt, Robot& robot) {
  v_ = approach(v_, wanted_v_, limits_.acc_lim_x * dt);
  w_ = approach(w_, wanted_w_, limits_.acc_lim_theta * dt);
  robot.velocity = v_ * Eigen::Vector2d(std::cos(robot.pose.yaw), std::sin(robot.pose.yaw));
  robot.yaw_rate = w_;
}

void DiffDrive::halt(Robot& robot) {
  wanted_v_ = wanted_w_ = v_ = w_ = 0.0;
  robot.velocity.setZero();
  robot.yaw_rate = 0.0;
}

}  // namespace rfbsim::sim
