// SPDX-License-Identifier: GPL-2.0-or-later
// World: the plain state of one simulation (what is where now). Systems read and write it; the renderer
// and the status reporter only read it. No GL, EGL or network types here.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "map/grid_map.hpp"
#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// A pose on the floor plane: metres and radians, yaw counter-clockwise from +x.
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
};

/// What a prop is, for drawing it; every kind blocks walking and the grid as its whole box.
enum class PropKind {
  Box,    ///< a crate
  Shelf,  ///< warehouse shelving: uprights and boards with goods
  Desk,   ///< a desk with a monitor
};

/// A box standing on the floor (crates, shelving, desks), turned by yaw about its centre.
struct Prop {
  double x = 0.0;       ///< centre, m
  double y = 0.0;       ///< centre, m
  double size_x = 0.5;  ///< full extent along its own x (yaw 0: world x), m
  double size_y = 0.5;  ///< full extent along its own y, m
  double height = 0.5;  ///< m
  std::uint32_t rgb = 0xb08850;  ///< colour 0xRRGGBB
  double yaw = 0.0;     ///< rad
  PropKind kind = PropKind::Box;
};

/// A visible marker on the floor, e.g. the participant's goal.
struct Landmark {
  std::string name;
  double x = 0.0;
  double y = 0.0;
  double radius = 0.3;  ///< m
  std::uint32_t rgb = 0xf2c12e;
};

/// A simulated pedestrian: what the crowd, the physics and the renderer share.
struct Person {
  int id = 0;                  ///< 1, 2, ... in scenario order
  Pose2 pose;                  ///< yaw: the way the body faces
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, as moved last tick
  double desired_speed = 1.34; ///< m/s, drawn per person
  double radius = 0.25;        ///< m, body radius for contacts
  double height = 1.75;        ///< m
  std::uint32_t rgb = 0x8a5a9e;  ///< shirt colour
  double gait_phase = 0.0;     ///< radians of the walking cycle
};

/// What the robot's navigator is doing (reported as events when it changes).
enum class RobotState { Idle, Planning, Moving, Recovering, Arrived, Failed };

/// Lower-case name of a state, as written in events and status.json ("moving").
inline const char* robot_state_name(RobotState state) {
  switch (state) {
    case RobotState::Idle: return "idle";
    case RobotState::Planning: return "planning";
    case RobotState::Moving: return "moving";
    case RobotState::Recovering: return "recovering";
    case RobotState::Arrived: return "arrived";
    case RobotState::Failed: return "failed";
  }
  return "unknown";
}

/// What the navigation stack last decided, for the debug overlay (`--debug-overlay`) and for status.
struct RobotNavView {
  std::vector<Eigen::Vector2d> global_path;       ///< world points, robot to goal; empty without a plan
  std::vector<Eigen::Vector2d> local_trajectory;  ///< the chosen DWA rollout, world points
  CostmapGrid social;     ///< the local costmap's proxemic costs (0 = none), a window around the robot
  std::optional<Pose2> goal;  ///< the current goal
};

/// The robot's navigator changed state (or began another recovery behaviour, or gave up).
struct RobotEvent {
  std::uint64_t tick = 0;
  RobotState state = RobotState::Idle;
  std::string detail;  ///< why, in words: "goal (10.00, 2.80)", "gave up: no global plan for 5.0 s: ..."
};

/// The robot: its physical state (written by physics and its drive) and what its stack believes and plans.
struct Robot {
  Pose2 pose;
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, world frame: wanted before physics, actual after
  double yaw_rate = 0.0;   ///< rad/s
  double radius = 0.16;    ///< m, Kuri's footprint
  double height = 0.5;     ///< m
  double head_yaw = 0.0;   ///< rad, the head turned against the body, toward where the robot is heading
  RobotState state = RobotState::Idle;
  Pose2 estimate;          ///< where localization believes the robot is (the pose the planners use)
  RobotNavView nav;
};

/// Who took part in a contact.
enum class Party { Avatar, Person, Robot, Static };

/// Two bodies touched during a tick; `impulse` (N s) is how hard, summed over the tick's contact points.
struct ContactEvent {
  std::uint64_t tick = 0;
  Party a = Party::Avatar;
  int a_index = 0;  ///< index into people for Party::Person; 0 otherwise
  Party b = Party::Static;
  int b_index = 0;
  double impulse = 0.0;
};

/// The participant's avatar.
struct Avatar {
  Pose2 pose;
  double speed = 0.0;         ///< signed forward speed, m/s (negative walking backwards)
  double yaw_rate = 0.0;      ///< rad/s
  double gait_phase = 0.0;    ///< radians of the walking cycle, advances with distance walked
  double distance_walked = 0.0;  ///< m, total
  /// m, body radius for contacts (physics) and for people keeping clear of it. An adult's shoulders are
  /// about 0.45 m (women) to 0.51 m (men) across on average (bideltoid breadth, ANSUR II 2012; see
  /// docs/sources.md), so a 0.25 m circle, as our pedestrians (Person) have. With the robot's 0.16 m the
  /// centres can meet at 0.41 m, so SEAN-EP's "within 0.45 m" can happen, as it did in the study.
  double radius = 0.25;
};

/// The third-person camera's adjustable part; where it is follows from the avatar each frame.
struct CameraRig {
  double height = 2.2;    ///< eye height above the floor, m (Up/Down change it)
  double distance = 3.2;  ///< horizontal distance behind the avatar, m
};

/// Everything that changes while the simulation runs, plus the static map it runs in.
struct World {
  GridMap map;        ///< the map file's walls only (drawn as walls, built as static physics boxes)
  GridMap obstacles;  ///< map with every prop blocked too: what route planning and wall forces use
  std::vector<Prop> props;
  std::vector<Landmark> landmarks;
  std::vector<Person> people;
  std::optional<Robot> robot;
  Avatar avatar;
  CameraRig camera;
  std::uint64_t tick = 0;  ///< fixed steps taken
  double time = 0.0;       ///< simulated seconds = tick * dt
  std::vector<ContactEvent> contacts;  ///< contacts that began during the last tick
  std::vector<RobotEvent> robot_events;  ///< the robot's state changes during the last tick
};

/// `map` with every prop's box blocked too: what World::obstacles holds.
inline GridMap with_props_blocked(GridMap map, const std::vector<Prop>& props) {
  for (const Prop& prop : props) map.block_box(prop.x, prop.y, prop.size_x, prop.size_y, prop.yaw);
  return map;
}

}  // namespace rfbsim::sim
