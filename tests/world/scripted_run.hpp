// SPDX-License-Identifier: GPL-2.0-or-later
// A scenario run with a scripted participant: keys pressed and released at given ticks, every agent's
// pose recorded at every tick.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/simulation.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::test {

struct ScriptedKey {
  std::uint64_t tick;     ///< applied before this tick is stepped
  std::uint32_t keysym;   ///< X11 keysym
  bool down;
};

/// The warehouse (or another shipped scenario) as sim_rfb would build it, with the given seed. Without
/// `robot_mission` the robot's stack runs but it is given no goal: it stands (tests of the crowd and pushes).
inline std::unique_ptr<sim::Simulation> make_scenario_simulation(const std::string& name, std::uint64_t seed,
                                                                 sim::ScenarioOverrides overrides = {},
                                                                 bool robot_mission = false) {
  sim::Scenario scenario = sim::load_scenario(std::string(RFBSIM_SCENARIO_DIR) + "/" + name + ".yaml");
  overrides.seed = seed;
  sim::apply_overrides(scenario, overrides);
  sim::RobotSetup robot = sim::robot_setup(scenario);
  if (!robot_mission) robot.mission = {};
  return std::make_unique<sim::Simulation>(sim::SimulationParams{}, sim::make_world(scenario), scenario.crowd,
                                           robot);
}

/// Every agent's x, y, yaw in a fixed order: avatar, people by index, robot.
inline std::vector<double> agent_poses(const sim::World& world) {
  std::vector<double> poses{world.avatar.pose.x, world.avatar.pose.y, world.avatar.pose.yaw};
  for (const sim::Person& person : world.people) {
    poses.insert(poses.end(), {person.pose.x, person.pose.y, person.pose.yaw});
  }
  if (world.robot) poses.insert(poses.end(), {world.robot->pose.x, world.robot->pose.y, world.robot->pose.yaw});
  return poses;
}

/// Steps `ticks` ticks applying `script`; returns the poses after every tick.
inline std::vector<std::vector<double>> run_scripted(sim::Simulation& simulation, const std::vector<ScriptedKey>& script,
                                                     std::uint64_t ticks) {
  std::vector<std::vector<double>> trace;
  trace.reserve(ticks);
  std::size_t next = 0;
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    while (next < script.size() && script[next].tick == tick) {
      simulation.apply_key(script[next].keysym, script[next].down);
      ++next;
    }
    simulation.step();
    trace.push_back(agent_poses(simulation.world()));
  }
  return trace;
}

}  // namespace rfbsim::test
