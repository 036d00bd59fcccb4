// SPDX-License-Identifier: GPL-2.0-or-later
// RobotMetrics: the robot's social-navigation measures (docs/sources.md) over one recorded session, taken
// at the trajectory's sample rate. The avatar counts as a person throughout.
#pragma once

#include <optional>

#include "session_samples.hpp"

namespace rfbsim::report {

/// The outer edge of Hall's social zone (docs/sources.md); the inner limits are NavMetrics' ZoneLimits.
constexpr double kSocialZoneLimit = 3.6;  // m

/// The robot's measures over a session's samples. Distances are between body centres.
struct RobotMetrics {
  double path_length = 0.0;           ///< m, summed between consecutive samples
  std::optional<double> path_ratio;   ///< path_length / straight first-to-last distance; none if that is < 0.1 m
  double heading_change = 0.0;        ///< rad, sum of |yaw change| (wrapped to [-pi, pi]) between samples
  double min_person_distance = 0.0;   ///< m, closest person or avatar at any sample
  double mean_closest_distance = 0.0; ///< m, the closest person's distance averaged over samples
  /// m, closest person at a sample where the robot was moving toward them faster than they toward it
  /// (NavMetrics); none if that never happened.
  std::optional<double> min_distance_robot_approaching;
  double pct_intimate = 0.0;  ///< % of samples with the closest person < 0.45 m
  double pct_personal = 0.0;  ///< % of samples with the closest person in [0.45, 1.2) m
  double pct_social = 0.0;    ///< % of samples with the closest person in [1.2, 3.6) m
  double pct_public = 0.0;    ///< % of samples with the closest person >= 3.6 m
  int robot_on_person = 0;    ///< collisions (gap < 0.02 m begun) with the robot closing faster
  int person_on_robot = 0;    ///< collisions begun otherwise
  double time_not_moving = 0.0;  ///< s: samples with robot speed < 0.01 m/s, times the sample interval
  double mean_speed = 0.0;       ///< m/s, the recorded speed averaged over samples
  std::optional<double> mean_abs_acceleration;  ///< m/s^2, from first differences of velocity; needs 2 samples
  std::optional<double> mean_abs_jerk;          ///< m/s^3, from second differences of velocity; needs 3 samples
};

/// The measures of `session`'s robot; none without a robot or without samples.
std::optional<RobotMetrics> robot_metrics(const SampledSession& session);

}  // namespace rfbsim::report
