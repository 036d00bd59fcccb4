// SPDX-License-Identifier: GPL-2.0-or-later
// The DWA's trajectory generator: window, samples, and exact-arc forward simulation.
#include "robot/planning/dwa_rollout.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::sim {

namespace {

// [centre - reach, centre + reach] clipped to [lo, hi]; if they do not overlap, the limit nearest the
// window, so a robot pushed past a limit is brought back within it.
void clip_window(double centre, double reach, double lo, double hi, double& out_lo, double& out_hi) {
  out_lo = std::max(lo, centre - reach);
  out_hi = std::min(hi, centre + reach);
  if (out_lo > out_hi) {
    const double nearest = centre - reach > hi ? hi : lo;
    out_lo = nearest;
    out_hi = nearest;
  }
}

}  // namespace

VelocityWindow dynamic_window(const DwaParams& params, double v, double w) {
  const double dt = 1.0 / params.controller_frequency;
  VelocityWindow window;
  clip_window(v, params.acc_lim_x * dt, params.min_vel_x, params.max_vel_x, window.v_min, window.v_max);
  clip_window(w, params.acc_lim_theta * dt, -params.max_vel_theta, params.max_vel_theta, window.w_min,
              window.w_max);
  return window;
}

void velocity_samples(double lo, double hi, int count, std::vector<double>& out) {
  out.clear();
  if (!(lo < hi)) {
    out.push_back(hi);
    return;
  }
  const int n = std::max(2, count);
  const double step = (hi - lo) / (n - 1);
  for (int i = 0; i < n; ++i) {
    // The last sample is hi exactly, not lo plus rounded steps.
    const double value = i == n - 1 ? hi : lo + step * i;
    out.push_back(value);
    const double next = i + 1 == n - 1 ? hi : lo + step * (i + 1);
    if (i + 1 < n && value < 0.0 && next > 0.0) out.push_back(0.0);
  }
}

bool roll_out(const Pose2& start, double v, double w, const DwaParams& params, Rollout& out) {
  out.v = v;
  out.w = w;
  out.poses.clear();
  // Enough steps that no step moves farther than sim_granularity nor turns more than angular_sim_granularity.
  const double steps_exact = std::max(std::abs(v) * params.sim_time / params.sim_granularity,
                                      std::abs(w) * params.sim_time / params.angular_sim_granularity);
  const auto steps = static_cast<std::size_t>(std::ceil(steps_exact));
  if (steps == 0) return false;
  const double dt = params.sim_time / static_cast<double>(steps);
  const auto extra = static_cast<std::size_t>(std::ceil(std::max(0.0, params.stop_time_buffer) / dt - 1e-9));
  out.end = steps;
  // Constant (v, w) moves along a circle of radius v / w (a line when w = 0): the closed form has no
  // integration error, whatever the step.
  const double c0 = std::cos(start.yaw);
  const double s0 = std::sin(start.yaw);
  for (std::size_t i = 0; i <= steps + extra; ++i) {
    const double t = dt * static_cast<double>(i);
    const double yaw = start.yaw + w * t;
    Pose2 pose{start.x, start.y, yaw};
    if (std::abs(w) < 1e-9) {
      pose.x += v * t * c0;
      pose.y += v * t * s0;
    } else {
      const double radius = v / w;
      pose.x += radius * (std::sin(yaw) - s0);
      pose.y -= radius * (std::cos(yaw) - c0);
    }
    out.poses.push_back(pose);
  }
  return true;
}

}  // namespace rfbsim::sim
