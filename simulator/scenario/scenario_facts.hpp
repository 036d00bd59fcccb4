// SPDX-License-Identifier: GPL-2.0-or-later
// What sim_manager reads of each offered scenario file, once at start-up: the spawn points a link may name,
// whether there is a robot, and the task's time limit and end grace (which a session's maximum duration must
// fit). Everything else in the file is sim_rfb's to check. The struct is plain data, so that the manager's pure
// link parser (start_request) uses it without YAML.
//
// Beside the simulator's scenario readers, not in the manager, so that the scenario format has one home; but a
// reader of its own rather than load_scenario(): the manager is C++17 and the scenario model's headers are C++20
// (GridMap's defaulted operator==, the costmaps' std::span), load_scenario also reads the map and checks every
// key (the manager must start with a scenario it cannot fully judge, and leave its errors to sim_rfb), and the
// manager's messages name the file, line and key in its own words. Both read the task's bounds from
// contract/task_bounds.hpp, and tests/contract checks that both agree on every shipped scenario.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::sim {

/// What the manager knows of one offered scenario from its file: the keys a link's parameters and a session's
/// maximum duration depend on. Everything else in the file is sim_rfb's to check.
struct ScenarioFacts {
  std::string name;                 ///< as offered (the config's NAME)
  std::string file;                 ///< the file read
  std::vector<std::string> spawns;  ///< `spawns`: the spawn points' names, in file order
  bool has_robot = false;           ///< the file has a `robot` (robot_start and robot_goal need one)
  /// `robot.control`: who drives the robot unless a link or the ros section says otherwise ("builtin" or
  /// "external"; a value sim_rfb would refuse reads as builtin here, and sim_rfb says what is wrong).
  std::string robot_control = "builtin";
  bool has_task = false;            ///< the file has a `task`: a clock, an outcome and an end
  double time_limit_s = 240.0;      ///< `task.time_limit`, s (sim_rfb's default, SEAN-EP's 4 min timer)
  double end_grace_s = 15.0;        ///< `task.end_grace`, s (sim_rfb's default)
};

/// Reads ScenarioFacts from a scenario file's text (`file` names it in errors). nullopt and `error` ("<file>:<line>:
/// task.time_limit: expected seconds 1..<contract::kMaxTimeLimitS>") when the text is not YAML or a key it reads
/// is malformed.
std::optional<ScenarioFacts> parse_scenario_facts(const std::string& text, const std::string& name,
                                                  const std::string& file, std::string& error);

/// The facts of every entry of a config's scenario list (NAME or NAME=FILE), in order: FILE, else NAME.yaml in
/// the first of `search_dirs` that has it (where sim_rfb looks). A NAME not found there is left out and named
/// in `missing` (its links are then not checked beyond their form); a FILE that cannot be read, or any file
/// that is malformed, sets `error` and returns what was read before it.
std::vector<ScenarioFacts> load_scenario_facts(const std::vector<std::string>& entries,
                                               const std::vector<std::filesystem::path>& search_dirs,
                                               std::string& error, std::vector<std::string>& missing);

}  // namespace rfbsim::sim
