// SPDX-License-Identifier: GPL-2.0-or-later
// SampledSession: trajectories.csv's rows gathered into whole samples (every agent once per sample tick),
// the form the report's metrics and plots read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "record/session_log.hpp"

namespace rfbsim::report {

/// One agent at one sample: map-frame metres, radians and metres per second.
struct AgentState {
  double x = 0.0, y = 0.0;
  double yaw = 0.0;
  double vx = 0.0, vy = 0.0;
};

/// Every agent of the session at one sample tick.
struct Sample {
  std::uint64_t tick = 0;
  double time = 0.0;  ///< simulated s
  AgentState avatar;
  std::optional<AgentState> robot;  ///< present whenever the session has a robot
  std::vector<AgentState> people;   ///< in the order of SampledSession::person_ids
};

/// A session's samples and its agents' bodies.
struct SampledSession {
  std::vector<Sample> samples;      ///< whole samples only, in tick order
  bool has_robot = false;
  /// m, from session.json (its reader requires a radius for every agent); the defaults are world.hpp's
  /// (sim::Avatar, sim::Robot) and only hold for a SampledSession built by hand.
  double avatar_radius = 0.25;
  double robot_radius = 0.16;       ///< m, as avatar_radius
  std::vector<int> person_ids;      ///< session.json's order
  std::vector<double> person_radii; ///< m, parallel to person_ids
  double sample_interval = 0.1;     ///< s, 1 / trajectory_hz
  /// Sample ticks left out because some agent had no row or more than one (a torn end, or a damaged
  /// file): a sample that lacks someone cannot give distances to everyone.
  std::size_t partial_samples = 0;
};

/// Gathers `log`'s trajectory rows by tick.
SampledSession assemble_samples(const sim::SessionLog& log);

}  // namespace rfbsim::report
