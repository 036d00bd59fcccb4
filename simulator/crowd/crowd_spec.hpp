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
  /// Person i walks routes[i % routes.size()], a list of points in metres (world frame), back and forth:
  /// to the last point, then back to the first, and so on. The start (a point on one of the route's
  /// segments) and the direction are drawn from the person's seed.
  std::vector<std::vector<Eigen::Vector2d>> routes;
  /// Without routes: each person starts near a goal drawn from these, walks to another drawn goal, then
  /// draws the next. Without routes and goals: goals are drawn from the map's free space.
  std::vector<Eigen::Vector2d> goals;
  double speed_mean = 1.34;  ///< m/s, desired walking speed N(mean, std) (libpedsim)
  double speed_std = 0.26;   ///< m/s
  double speed_min = 0.5;    ///< m/s, draws are clamped to [min, max]
  double speed_max = 2.0;    ///< m/s
  std::uint64_t seed = 1;    ///< every person's random stream derives from it
};

}  // namespace rfbsim::sim
