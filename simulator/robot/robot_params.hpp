// SPDX-License-Identifier: GPL-2.0-or-later
// RobotParams: the whole robot's model in one place: base, sensors, localization, costmaps, planners and
// navigator. Defaults follow docs/sources.md (SEAN's Kuri and the SEAN-EP move_base); a scenario's
// `robot.nav` section overrides them by ROS name (docs/scenarios.md).
#pragma once

#include "robot/costmap/costmap_params.hpp"
#include "robot/diff_drive.hpp"
#include "robot/navigator_params.hpp"
#include "robot/planning/dwa_planner.hpp"
#include "robot/planning/global_planner.hpp"
#include "robot/sensing/amcl.hpp"
#include "robot/sensing/lidar.hpp"
#include "robot/sensing/odometry.hpp"

namespace rfbsim::sim {

/// Where the planners' pose comes from.
enum class Localization {
  Amcl,         ///< the particle filter's estimate (odometry drift and lidar noise matter)
  GroundTruth,  ///< the true pose: for studies that do not want localization error
};

/// The global costmap as the robot uses it: inflation 0.55 m (nav2's default) instead of SEAN's 0.3 m.
/// The planner's cost (50 + 3c, capped at 252) is at its cap wherever c >= 67, which with a scaling factor
/// of 3 is everywhere inflated out to 0.65 m: with 0.3 m, paths hugged racking at 0.33 m and DWA, cutting
/// the corner at an aisle's end, wedged the robot against the rack; with 0.55 m paths keep 0.55 m off
/// walls and racking, and a person's proxemic cost still decides which side of a corridor to take.
inline CostmapParams robot_global_costmap_params() {
  CostmapParams params = global_costmap_params();
  params.inflation.inflation_radius = 0.55;
  return params;
}

/// The global planner as the robot uses it: a goal someone stands on is moved to the nearest free cell
/// within 0.5 m (ROS's default_tolerance 0 would refuse the participant's start while they stand on it).
inline GlobalPlannerParams default_global_planner_params() {
  GlobalPlannerParams params;
  params.default_tolerance = 0.5;
  return params;
}

/// The robot's whole model: every part's parameters.
struct RobotParams {
  DriveLimits drive;
  LidarParams lidar;
  OdometryParams odometry;
  Localization localization = Localization::Amcl;
  AmclParams amcl;
  CostmapParams global_costmap = robot_global_costmap_params();
  /// The local costmap inflates 0.45 m, not SEAN's 0.1 m: our DWA checks the robot's centre cell against
  /// inscribed cost (a round robot's exact footprint test), which needs inflation past the padded radius
  /// (ROS's DWA checked the footprint's outline against the map instead), and with occdist_scale 0.1 the
  /// graded cost keeps the robot off walls and people rather than on the inscribed edge.
  CostmapParams local_costmap = local_costmap_params(0.45);
  /// Hz: how often the global costmap takes in the latest scan and people (ROS's update_frequency);
  /// the local one is updated every control cycle.
  double global_update_frequency = 2.0;
  GlobalPlannerParams planner = default_global_planner_params();
  DwaParams dwa;
  NavigatorParams navigator;
  /// m added to the robot's radius for the costmaps' footprint and inscribed radius (ROS's
  /// footprint_padding, 0.01 there): at 0.01 the local planner let the robot brush past people 1-2 cm away
  /// (a collision by docs/sources.md's 2 cm rule) in 5 of 50 warehouse trials.
  double footprint_padding = 0.05;
  double head_max_rate = 3.0;   ///< rad/s the head turns at most
  double head_lookahead = 1.0;  ///< m along the global path the head looks at
  double head_max_angle = 1.4;  ///< rad the head turns at most from the body's front
};

}  // namespace rfbsim::sim
