// SPDX-License-Identifier: GPL-2.0-or-later
// CrowdSpec: who walks where in a scenario (filled by the scenario loader, used by the crowd system).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace rfbsim::sim {

/// The pedestrians of a scenario: how many, where they walk, how fast, from which seed.
struct CrowdSpec {
  int count = 0;  ///< number of people
  /// Person i walks routes[i % routes.size()], a list of points in metres (world frame).
  std::vector<std::vector<Eigen::Vector2d>> routes;
  /// Without routes: each person walks to a goal drawn from these, then draws the next.
  std::vector<Eigen::Vector2d> goals;
  double speed_mean = 1.34;  ///< m/s, desired walking speed N(mean, std) (libpedsim)
  double speed_std = 0.26;   ///< m/s
  double speed_min = 0.5;    ///< m/s, draws are clamped to [min, max]
  double speed_max = 2.0;    ///< m/s
  std::uint64_t seed = 1;    ///< every person's random stream derives from it
};

}  // namespace rfbsim::sim
