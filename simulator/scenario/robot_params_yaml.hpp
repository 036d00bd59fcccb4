// SPDX-License-Identifier: GPL-2.0-or-later
// The `robot.nav` section of a scenario: overrides of the robot's parameters by ROS name, grouped as ROS
// groups them (move_base, global_planner, dwa, global_costmap, local_costmap, amcl, ...). docs/scenarios.md
// lists every key with its unit and default.
#pragma once

#include "robot/robot_params.hpp"
#include "scenario/yaml_field.hpp"

namespace rfbsim::sim {

/// Applies the keys of `nav` to `params`. Throws ScenarioError naming the file, line and key for an
/// unknown section or key, a value of the wrong kind or out of range, or parameters that cannot work
/// together (e.g. a lidar whose range_max is below its range_min).
void parse_robot_params(const YamlField& nav, RobotParams& params);

}  // namespace rfbsim::sim
