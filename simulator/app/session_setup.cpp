// SPDX-License-Identifier: GPL-2.0-or-later
// SessionSetup: from a scenario and its parameters to a running Simulation.
#include "app/session_setup.hpp"

#include <charconv>

#include "record/digest.hpp"
#include "scenario/scenario.hpp"
#include "world/demo_world.hpp"

namespace rfbsim::sim {

namespace {

ScenarioOverrides overrides_of(const SessionSetup& setup) {
  ScenarioOverrides overrides;
  overrides.seed = setup.seed;
  for (const auto& [name, value] : setup.parameters) {
    if (name == "avatar_start") {
      overrides.avatar_start = value;
    } else if (name == "avatar_goal") {
      overrides.avatar_goal = value;
    } else if (name == "robot_start") {
      overrides.robot_start = value;
    } else if (name == "robot_goal") {
      overrides.robot_goal = value;
    } else if (name == "robot_control") {
      overrides.robot_control = value;
    } else if (name == "camera") {
      overrides.camera = value;
    } else if (name == "crowd") {
      int count = -1;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), count);
      if (ec != std::errc() || end != value.data() + value.size()) {
        throw ScenarioError("--crowd: expected a number of people, got '" + value + "'");
      }
      overrides.crowd_count = count;
    } else {
      throw ScenarioError("unknown scenario parameter '" + name + "'");
    }
  }
  return overrides;
}

}  // namespace

const char* rfbsim_version() { return RFBSIM_VERSION; }
const char* rfbsim_build_id() { return RFBSIM_BUILD_ID; }

PreparedSession prepare_session(const SessionSetup& setup) {
  SimulationParams params;
  params.dt = 1.0 / setup.tick_hz;
  PreparedSession prepared;
  SessionInfo& info = prepared.info;
  info.tick_hz = setup.tick_hz;
  info.parameters = setup.parameters;
  if (setup.seed) info.parameters.emplace_back("seed", std::to_string(*setup.seed));
  info.rfbsim_version = rfbsim_version();
  info.build = rfbsim_build_id();
  if (setup.scenario.empty()) {
    // The view is no part of the room: the test room takes --camera, and nothing else.
    for (const auto& [name, value] : setup.parameters) {
      if (name != "camera") throw ScenarioError("the built-in test room takes no scenario parameters");
      const auto mode = camera_mode_from_name(value);
      if (!mode) throw ScenarioError("--camera: expected 'third_person' or 'first_person', got '" + value + "'");
      prepared.camera = *mode;
    }
    info.camera = std::string(camera_mode_name(prepared.camera));
    prepared.simulation = std::make_unique<Simulation>(params, make_demo_world());
    return prepared;
  }
  const auto file = find_scenario(setup.scenario, {RFBSIM_SOURCE_SCENARIOS, RFBSIM_INSTALLED_SCENARIOS});
  Scenario scenario = load_scenario(file);
  apply_overrides(scenario, overrides_of(setup));
  if (setup.time_limit) scenario.task.time_limit = *setup.time_limit;
  if (setup.end_grace) scenario.task.end_grace = *setup.end_grace;

  info.scenario = scenario.name;
  if (scenario.robot.present) info.robot_control = robot_control_name(scenario.robot.control);
  info.scenario_file = std::filesystem::absolute(file).lexically_normal().string();
  info.seed = scenario.seed;
  info.scenario_sha256 = sha256_file(file);
  info.map_sha256 = sha256_file(scenario.map_image);
  for (const TaskStep& step : scenario.task.steps) info.tasks.emplace_back(task_type_name(step.type), task_step_text(step));
  if (!scenario.task.steps.empty()) {
    info.time_limit = scenario.task.time_limit;
    info.end_grace = scenario.task.end_grace;
  }
  prepared.task = scenario.task;
  prepared.camera = scenario.camera;
  info.camera = std::string(camera_mode_name(scenario.camera));
  prepared.simulation = std::make_unique<Simulation>(params, make_world(scenario), scenario.crowd, robot_setup(scenario));
  return prepared;
}

}  // namespace rfbsim::sim
