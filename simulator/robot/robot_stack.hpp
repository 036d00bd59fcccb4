// SPDX-License-Identifier: GPL-2.0-or-later
// RobotStack: the robot stage of the tick (sense, localize, plan, act). Every tick it integrates odometry
// and ramps the wheels; at the lidar's rate it casts a scan; at the controller's rate it localizes, updates
// the costmaps with the scan and the people in view, runs the navigator and commands the drive. The mission
// hands the navigator its goals. It writes the robot's wanted velocity (physics moves the body), its head,
// what it believes and plans (Robot::estimate, Robot::nav) and its state changes (World::robot_events).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "robot/costmap/layered_costmap.hpp"
#include "robot/mission.hpp"
#include "robot/navigator.hpp"
#include "robot/robot_params.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// Who drives the robot: its own navigation stack, or a controller outside (a lab's ROS stack over rosbridge,
/// docs/ros.md) whose velocity commands go straight to the wheels.
enum class RobotControl { kBuiltin, kExternal };

/// "builtin" or "external", as scenarios, links, flags and session data spell it.
const char* robot_control_name(RobotControl control);
/// The control named `name` ("builtin" or "external"); none for anything else.
std::optional<RobotControl> robot_control_from_name(std::string_view name);

/// Everything that configures one robot in a session: its model, its mission and its random streams' seed.
struct RobotSetup {
  RobotParams params;
  MissionSpec mission;
  std::uint64_t seed = 1;
  RobotControl control = RobotControl::kBuiltin;
  /// s of simulated time after the last external command when the robot stops (the watchdog; ROS's
  /// controllers commonly use 0.5 s). External control only.
  double command_timeout = 0.5;
};

/// The velocity the wheels were last told to reach (the navigator's, or an external controller's).
struct DriveCommand {
  double v = 0.0;              ///< m/s forward
  double w = 0.0;              ///< rad/s counter-clockwise
  double time = 0.0;           ///< simulated s when it was given
  std::uint64_t sequence = 0;  ///< commands given so far: a reader sees a new one when this changes
};

/// The stages of the stack whose cost bench_nav reports.
enum class NavStage { Lidar, Localization, Costmaps, GlobalPlan, LocalPlan, Count };

/// Wall-clock cost per stage: total seconds and how many times it ran (measurement only; no decision
/// depends on it, so runs stay deterministic).
struct StageTimes {
  std::array<double, static_cast<int>(NavStage::Count)> seconds{};
  std::array<std::uint64_t, static_cast<int>(NavStage::Count)> runs{};
};

/// The robot stage of the tick for one robot (see the top of this file).
class RobotStack {
 public:
  /// Builds the stack for `world`'s robot (which must exist) in `world`'s obstacles map. Throws
  /// std::invalid_argument when a parameter cannot work (the message names it).
  RobotStack(const World& world, RobotSetup setup);
  ~RobotStack();
  RobotStack(const RobotStack&) = delete;
  RobotStack& operator=(const RobotStack&) = delete;

  /// One tick of dt seconds, before physics. Replaces world.robot_events with this tick's state changes.
  void step(World& world, double dt);
  /// Sends the robot to `goal` now (the mission's next goals follow when it arrives). Returns the reason
  /// when the goal is refused (inside a wall or prop, or off the map).
  std::optional<std::string> send_goal(World& world, const Pose2& goal);
  /// External control: the wheels aim for (v, w) from the next tick until a newer command, or until
  /// command_timeout passes without one (then the robot stops, and a RobotEvent says so). Non-finite values
  /// read as stop. Ignored, returning false, under built-in control.
  bool external_command(const World& world, double v, double w);

  [[nodiscard]] RobotControl control() const { return setup_.control; }
  /// The wheel odometry's pose, in the odom frame (which starts as the map frame and drifts).
  [[nodiscard]] const Pose2& odometry_pose() const { return odometry_.pose(); }
  /// The lidar's latest sweep (empty ranges before the first) and how many sweeps were cast so far.
  [[nodiscard]] const LaserScan& last_scan() const { return scan_; }
  [[nodiscard]] std::uint64_t scans() const { return scans_; }
  /// What the wheels were last told, and their actual forward speed and turn rate now.
  [[nodiscard]] const DriveCommand& last_command() const { return command_; }
  [[nodiscard]] double wheel_v() const { return drive_.v(); }
  [[nodiscard]] double wheel_w() const { return drive_.w(); }
  /// The goal the scenario's mission gives the robot now, under either control (none without a mission).
  [[nodiscard]] const std::optional<Pose2>& mission_goal() const { return mission_goal_; }

  [[nodiscard]] const StageTimes& stage_times() const { return times_; }
  [[nodiscard]] const Navigator& navigator() const { return navigator_; }
  [[nodiscard]] const LayeredCostmap& global_costmap() const { return global_; }
  [[nodiscard]] const LayeredCostmap& local_costmap() const { return local_; }
  [[nodiscard]] const RobotParams& params() const { return setup_.params; }
  /// Control cycles run so far.
  [[nodiscard]] std::uint64_t cycles() const { return cycles_; }

 private:
  void control_cycle(World& world);
  Pose2 localize(Robot& robot);
  void next_mission_goal(World& world);
  void record_events(World& world);
  void turn_head(Robot& robot, double dt) const;
  void command_drive(double v, double w, double now);
  void external_cycle(World& world);
  void watch_external_commands(World& world);
  void external_goal_reached(World& world);

  RobotSetup setup_;
  DiffDrive drive_;
  WheelOdometry odometry_;
  std::optional<Amcl> amcl_;
  LayeredCostmap global_;
  LayeredCostmap local_;
  Navigator navigator_;
  MissionRunner mission_;
  std::mt19937_64 lidar_rng_;
  // Buffers reused every scan and cycle.
  LaserScan scan_;
  bool scan_fresh_ = false;  // a scan was cast since the last control cycle
  std::vector<LidarBody> bodies_;
  std::vector<SeenPerson> seen_;
  // Schedules, in ticks of the world.
  double next_scan_time_ = 0.0;
  double next_cycle_time_ = 0.0;
  double next_global_update_ = 0.0;
  double resume_mission_at_ = -1.0;  // a pause at a waypoint ends then; < 0 = no pause
  bool goal_finished_ = false;       // the current goal was reached or failed, and the mission was told
  bool mission_started_ = false;     // the mission's first goal was handed out (or a goal was sent)
  std::uint64_t cycles_ = 0;
  StageTimes times_;
  double head_target_ = 0.0;  // rad against the body, where the head should look
  std::uint64_t scans_ = 0;
  DriveCommand command_;
  std::optional<Pose2> mission_goal_;
  // External control: the latest command's (v, w) and time; whether the watchdog has stopped the robot.
  double external_v_ = 0.0, external_w_ = 0.0, external_time_ = -1.0;
  bool external_stale_ = true;
};

/// The people the robot's lidar can see from `pose` in `world`: each person and the avatar whose centre is
/// within `range` and not hidden behind a wall or prop (a people detector's output: position and velocity).
void people_in_view(const World& world, const Pose2& pose, double range, std::vector<SeenPerson>& out);

}  // namespace rfbsim::sim
