// SPDX-License-Identifier: GPL-2.0-or-later
// NavigatorParams: move_base's own parameters (names as in ROS), the goal tolerances and the recovery
// behaviours. The planners' and costmaps' parameters live with them.
#pragma once

namespace rfbsim::sim {

/// move_base's parameters (ROS names; defaults and deviations in docs/architecture.md, "The robot").
struct NavigatorParams {
  double controller_frequency = 10.0;  ///< Hz: costmaps, local planning and commands (ROS 20; the issue's 10)
  /// Hz: the global plan is remade this often while moving, so it bends around people as they come
  /// (ROS's default 0 plans once; a crowd makes the first plan stale within seconds).
  double planner_frequency = 1.0;
  double planner_patience = 5.0;     ///< s without any plan before recovery (ROS 5)
  double controller_patience = 5.0;  ///< s without a legal velocity before recovery (ROS 15: too long to
                                     ///< stand still in front of a participant)
  double xy_goal_tolerance = 0.35;   ///< m (SEAN-EP's move_base)
  double yaw_goal_tolerance = 3.15;  ///< rad; pi or more ignores the goal's heading (missions give places)
  /// s without moving oscillation_distance before recovery; ROS's default 0 never times out, which would
  /// leave a robot dithering in a blocked doorway for ever.
  double oscillation_timeout = 30.0;
  double oscillation_distance = 0.5;  ///< m
  bool recovery_behavior_enabled = true;
  double conservative_reset_dist = 3.0;  ///< m: first recovery forgets obstacles farther than this
  double aggressive_reset_dist = 0.64;   ///< m (4 x Kuri's radius): the later recovery forgets more
  /// m, centre to centre: where someone stands at the goal (within this distance of it, slower than
  /// walking), the goal is that person, and the robot stops this far from them. 1.2 m is Hall's boundary
  /// between the personal and the social zone (docs/sources.md / docs/sources.md): the robot sent to the
  /// participant's start (SEAN-EP's mission) waits at social distance instead of walking into their space.
  double person_goal_distance = 1.2;
  /// m/s: a person at the goal slower than this is standing there (a walker crossing the goal is not a goal).
  double person_goal_standing_speed = 0.1;
  /// rad: when the path ahead (rotate_lookahead along it) lies further than this from the robot's heading,
  /// the robot turns in place toward it before DWA drives (as nav2's rotation shim does). DWA alone scores
  /// every turn in place alike when the path is behind the robot, so it stalls facing a blocked corridor.
  double rotate_to_path_angle = 1.2;
  double rotate_lookahead = 0.6;         ///< m along the path
  double waypoint_pause = 2.0;           ///< s a patrolling or wandering robot waits at each waypoint
};

}  // namespace rfbsim::sim
