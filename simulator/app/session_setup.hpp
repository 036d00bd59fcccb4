// SPDX-License-Identifier: GPL-2.0-or-later
// SessionSetup: what makes one session's world (scenario, overrides, seed, rates), and the Simulation,
// task and session-data header made from it. sim_rfb makes it from its command line; sim_replay from a
// recorded session.json, so that both build the very same world.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/simulation.hpp"
#include "record/session_writer.hpp"
#include "task/task_spec.hpp"
#include "world/camera_mode.hpp"

namespace rfbsim::sim {

struct SessionSetup {
  std::string scenario;  ///< name or path; empty = the built-in test room
  /// Overrides as (link parameter, value): avatar_start, avatar_goal, robot_start, robot_goal, crowd,
  /// robot_control, camera.
  std::vector<std::pair<std::string, std::string>> parameters;
  std::optional<std::uint64_t> seed;  ///< unset = the scenario's (and its crowd's own, if it has one)
  int tick_hz = 60;
  std::optional<double> time_limit;  ///< s, overrides the scenario's task time limit
  std::optional<double> end_grace;   ///< s, overrides the scenario's task end_grace
};

/// A session ready to run.
struct PreparedSession {
  std::unique_ptr<Simulation> simulation;
  TaskSpec task;
  CameraMode camera = CameraMode::kThirdPerson;  ///< the participant's view: the scenario's, or the override
  /// session.json's header, less what the caller knows (uid, fps, frame, codes). Its parameters are the
  /// setup's, plus "seed" when the setup gave one: what a replay needs to build the same world (a seed
  /// override also replaces a crowd's own seed, so "given" and "the file's" are not the same).
  SessionInfo info;
};

/// Loads the scenario (found by name in the source and installed scenario folders, or as a path),
/// applies the parameters, and builds everything. Throws ScenarioError for a bad scenario or parameter.
PreparedSession prepare_session(const SessionSetup& setup);

/// This build's version and build id, as session.json's `versions` records them.
const char* rfbsim_version();
const char* rfbsim_build_id();

}  // namespace rfbsim::sim
