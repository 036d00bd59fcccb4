// SPDX-License-Identifier: GPL-2.0-or-later
// Scenario: what one study condition is made of (the model, in STYLE.md's sense): the map, props,
// landmarks, named spawn points, the crowd, the robot's start and mission, the participant's start and
// goal. Loaded from a YAML file (docs/scenarios.md); the link or command line may override poses, seed
// and crowd size. make_world() turns it into the initial World.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "crowd/crowd_spec.hpp"
#include "robot/mission.hpp"
#include "robot/robot_stack.hpp"
#include "task/task_spec.hpp"
#include "world/camera_mode.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// A scenario or map file is wrong; the message names the file, the key and what was expected.
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A named place where links can start the avatar or the robot, or send them.
struct SpawnPoint {
  std::string name;
  Pose2 pose;
};

struct RobotSpec {
  bool present = false;
  Pose2 start;
  MissionSpec mission;
  RobotParams params;  ///< defaults, overridden by the file's `robot.nav`
  /// `robot.control`: the built-in stack drives, or an external controller over ROS (docs/ros.md).
  RobotControl control = RobotControl::kBuiltin;
  double command_timeout = 0.5;  ///< `robot.command_timeout`, s: external control's watchdog
};

struct Scenario {
  std::string name;                 ///< the file's `name`, else its stem
  std::filesystem::path file;       ///< where it was loaded from
  std::filesystem::path map_file;   ///< the ROS map YAML
  std::filesystem::path map_image;  ///< the map's picture (what session data's map_sha256 is taken of)
  GridMap map;                      ///< walls from the map file
  std::vector<Prop> props;
  std::vector<Landmark> landmarks;
  std::vector<SpawnPoint> spawns;   ///< in file order
  CrowdSpec crowd;
  RobotSpec robot;
  Pose2 avatar_start;
  std::optional<Landmark> avatar_goal;  ///< drawn as a landmark; what the participant walks to
  std::uint64_t seed = 1;               ///< master seed; the crowd's comes from it unless given
  TaskSpec task;                        ///< the participant's task; no steps = none (reach targets resolved)
  CameraMode camera = CameraMode::kThirdPerson;  ///< `camera`: the participant's view
};

/// Loads and checks a scenario file and its map. Throws ScenarioError (never anything else for bad
/// content): "<file>: key 'crowd.count': expected an integer 0..500, got 'many'".
Scenario load_scenario(const std::filesystem::path& file);

/// Where a scenario named on the command line lives: an existing path as given, else NAME.yaml in the
/// first of `search_dirs` that has it. Throws ScenarioError listing the known names when none does.
std::filesystem::path find_scenario(const std::string& name_or_path,
                                    const std::vector<std::filesystem::path>& search_dirs);

/// Command-line or link overrides; each pose is a spawn name or "x,y,yaw" (yaw in radians, optional for
/// goals).
struct ScenarioOverrides {
  std::optional<std::string> avatar_start;
  std::optional<std::string> avatar_goal;
  std::optional<std::string> robot_start;
  std::optional<std::string> robot_goal;
  std::optional<std::uint64_t> seed;
  std::optional<int> crowd_count;
  std::optional<std::string> robot_control;  ///< "builtin" or "external" (--robot-control, the link's robot_control)
  std::optional<std::string> camera;         ///< "third_person" or "first_person" (--camera, the link's camera)
};

/// Applies overrides and re-checks the poses against the map. Throws ScenarioError naming the option
/// ("--avatar-start: no spawn point 'dok' in warehouse (known: dock, aisle_a, ...)").
void apply_overrides(Scenario& scenario, const ScenarioOverrides& overrides);

/// The robot's setup for a Simulation: its parameters, its mission, and a seed derived from the scenario's.
RobotSetup robot_setup(const Scenario& scenario);

/// The initial world: map, obstacles (map + props), props, landmarks (with the avatar's goal), avatar
/// and robot at their starts. People are added by the crowd system.
World make_world(const Scenario& scenario);

}  // namespace rfbsim::sim
