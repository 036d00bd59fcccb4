// SPDX-License-Identifier: GPL-2.0-or-later
// The warehouse trials of issue 4: the robot crosses the warehouse (north_middle <-> dock, 25 m as the crow
// flies, through the racking aisles) among 15 pedestrians, one seed per trial. The participant's avatar is
// parked in the office, out of the way. Shared by the test (thresholds) and bench_nav (the table).
#pragma once

#include <cstdint>

#include "nav_run.hpp"

namespace rfbsim::test {

inline constexpr int kWarehouseTrials = 50;
inline constexpr double kWarehouseTrialLimit = 300.0;  ///< s of simulated time before a trial times out

/// Trial `seed`: even seeds north_middle -> dock, odd ones the other way.
inline NavRun warehouse_trial(std::uint64_t seed, const sim::RobotStack** stack_out = nullptr,
                              std::unique_ptr<sim::Simulation>* keep = nullptr) {
  sim::ScenarioOverrides overrides;
  overrides.avatar_start = "office";
  overrides.robot_start = seed % 2 == 0 ? "north_middle" : "dock";
  overrides.robot_goal = seed % 2 == 0 ? "dock" : "north_middle";
  auto simulation = make_mission_simulation("warehouse", seed, overrides);
  NavRun run = run_to_goal(*simulation, kWarehouseTrialLimit);
  if (stack_out) *stack_out = simulation->robot_stack();
  if (keep) *keep = std::move(simulation);
  return run;
}

}  // namespace rfbsim::test
