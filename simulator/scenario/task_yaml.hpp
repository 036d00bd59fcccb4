// SPDX-License-Identifier: GPL-2.0-or-later
// The `task` section of a scenario: the participant's steps, the time limit and the grace period
// (docs/scenarios.md).
#pragma once

#include <string>
#include <vector>

#include "scenario/yaml_field.hpp"
#include "task/task_spec.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// Parses `task` into a spec. Reach steps name a landmark from `landmarks` (checked here) or none (the
/// avatar's goal, resolved later with resolve_task_targets). Throws ScenarioError naming file, line and key.
TaskSpec parse_task(const YamlField& task, const std::vector<Landmark>& landmarks);

/// Fills each Reach step's target: its landmark, else `avatar_goal`. Throws ScenarioError when a step
/// needs the avatar's goal and the scenario has none.
void resolve_task_targets(TaskSpec& spec, const std::vector<Landmark>& landmarks, const Landmark* avatar_goal);

}  // namespace rfbsim::sim
