// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA's trajectory generator: the dynamic window, the velocities sampled in it, and the forward
// simulation of one constant (v, w) command.
#pragma once

#include <cstddef>
#include <vector>

#include "robot/planning/dwa_params.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// The velocities reachable within one control period, intersected with the limits.
struct VelocityWindow {
  double v_min = 0.0;  ///< m/s
  double v_max = 0.0;  ///< m/s
  double w_min = 0.0;  ///< rad/s
  double w_max = 0.0;  ///< rad/s
};

/// [v - acc_lim_x dt, v + acc_lim_x dt] and the same for w (dt = 1 / controller_frequency), clipped to the
/// limits. A robot already beyond a limit (pushed) gets the single limit value nearest its window.
VelocityWindow dynamic_window(const DwaParams& params, double v, double w);

/// Replaces `out` with `count` evenly spaced values from lo to hi, both included (at least 2 unless
/// lo == hi), plus 0 where it falls strictly between two of them, as ROS's velocity iterator does.
void velocity_samples(double lo, double hi, int count, std::vector<double>& out);

/// One forward simulation: poses[0] is the start, poses[end] the pose after sim_time, and the poses after
/// that continue for stop_time_buffer (checked for obstacles, not scored).
struct Rollout {
  double v = 0.0;  ///< m/s
  double w = 0.0;  ///< rad/s
  std::vector<Pose2> poses;
  std::size_t end = 0;  ///< index of the pose at sim_time
};

/// Simulates (v, w) from `start` along its exact arc, in steps no longer than sim_granularity (m) nor
/// angular_sim_granularity (rad), reusing `out`'s storage. Returns false for a command that does not move
/// (v = w = 0): such a rollout has no steps (as in ROS).
bool roll_out(const Pose2& start, double v, double w, const DwaParams& params, Rollout& out);

}  // namespace rfbsim::sim
