// SPDX-License-Identifier: GPL-2.0-or-later
// Navigator: move_base's state machine for one goal at a time. Each control cycle it replans on the global
// costmap when due, asks DWA for a velocity on the local costmap, checks the goal tolerance, and runs the
// recovery behaviours (clear, rotate, clear more, rotate, give up with a reason) when it is stuck. It reads
// costmaps and a pose; it asks its caller to clear costmaps rather than owning them.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"
#include "robot/costmap/seen_person.hpp"
#include "robot/navigator_params.hpp"
#include "robot/planning/dwa_planner.hpp"
#include "robot/planning/global_planner.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// A state change, as the robot reports it.
struct NavEvent {
  RobotState state = RobotState::Idle;
  std::string detail;  ///< why: "goal (10.00, 2.80)", "no legal velocity for 5.0 s: ...", ...
};

/// Wall-clock cost of the planners so far (measurement only).
struct NavigatorTimes {
  double plan_seconds = 0.0;     ///< s spent in global planning
  std::uint64_t plans = 0;       ///< global plans made
  double control_seconds = 0.0;  ///< s spent in local planning (DWA)
  std::uint64_t controls = 0;    ///< DWA cycles run
};

/// What one cycle asks of the rest of the robot.
struct NavCommand {
  double v = 0.0;  ///< m/s wanted forward speed
  double w = 0.0;  ///< rad/s wanted turn rate
  /// When set: forget obstacle marks farther than this from the robot, in both costmaps (a recovery).
  std::optional<double> clear_obstacles_beyond;
};

/// The first point of `path` at least `distance` m from `from`, after the path's point nearest `from`
/// (the path's last point when none is that far); none when the path has fewer than two points or its
/// nearest point is its last. What the robot turns toward, and what its head looks at.
std::optional<Eigen::Vector2d> point_ahead(const std::vector<Eigen::Vector2d>& path, const Eigen::Vector2d& from,
                                           double distance);

/// The person the robot's goal is: of `people`, the one nearest `goal` among those standing (slower than
/// params.person_goal_standing_speed) within params.person_goal_distance of it; none if nobody is.
std::optional<Eigen::Vector2d> goal_person_at(const Pose2& goal, std::span<const SeenPerson> people,
                                              const NavigatorParams& params);

/// move_base for one goal at a time: plan, control, goal check, recoveries (see the top of this file).
class Navigator {
 public:
  Navigator(NavigatorParams params, GlobalPlannerParams planner, DwaParams dwa);

  /// Takes a new goal. A goal off `map` or where the robot's footprint (radius m) would overlap a wall or
  /// prop is refused: the state becomes Failed, and the reason is returned (and reported as an event).
  std::optional<std::string> set_goal(const Pose2& goal, const GridMap& map, double radius);
  /// The people the robot sees now (the local planner keeps clear of where they are heading).
  void set_people(std::span<const SeenPerson> people) { dwa_.set_people(people); }
  /// Drops the goal: Idle.
  void cancel();

  /// One control cycle at time `now` (s) from the estimated pose and the drive's current (v, w).
  /// `goal_person`: where the person standing at the goal is (m; goal_person_at picks them), if anyone is:
  /// the robot then arrives person_goal_distance from them.
  NavCommand cycle(double now, const Pose2& pose, double v, double w, const CostmapGrid& global,
                   const CostmapGrid& local, std::optional<Eigen::Vector2d> goal_person = std::nullopt);

  [[nodiscard]] RobotState state() const { return state_; }
  [[nodiscard]] const std::string& detail() const { return detail_; }
  [[nodiscard]] const std::optional<Pose2>& goal() const { return goal_; }
  [[nodiscard]] const std::vector<Eigen::Vector2d>& global_path() const { return path_; }
  [[nodiscard]] const std::vector<Eigen::Vector2d>& local_trajectory() const { return trajectory_; }
  /// State changes since the last call, oldest first.
  std::vector<NavEvent> take_events();
  [[nodiscard]] const NavigatorParams& params() const { return params_; }
  [[nodiscard]] const NavigatorTimes& times() const { return times_; }

 private:
  // Recovery behaviours in order: clear far obstacles, rotate, clear near obstacles, rotate; then give up.
  static constexpr int kRecoverySteps = 4;
  void enter(RobotState state, std::string detail);
  void start_recovery(double now, const Pose2& pose, std::string trigger);
  NavCommand recover(double now, const Pose2& pose, double w, const CostmapGrid& local);
  bool replan(double now, const Pose2& pose, const CostmapGrid& global);
  bool goal_reached(const Pose2& pose, const std::optional<Eigen::Vector2d>& goal_person) const;
  /// World direction from the robot to the path point rotate_lookahead on from the nearest one (the path's
  /// last point when it ends nearer); none without a path of two points or more.
  std::optional<double> path_bearing(const Pose2& pose) const;
  void track_progress(double now, const Pose2& pose);

  NavigatorParams params_;
  NavigatorTimes times_;
  GlobalPlanner planner_;
  DwaPlanner dwa_;
  RobotState state_ = RobotState::Idle;
  std::string detail_;
  std::vector<NavEvent> events_;
  std::optional<Pose2> goal_;
  std::vector<Eigen::Vector2d> path_;
  std::vector<Eigen::Vector2d> trajectory_;
  // Timers of move_base: the last good plan and control, and the last time the robot made progress.
  double last_plan_time_ = -1e9;      // when a plan was last attempted
  double last_valid_plan_ = 0.0;
  double last_valid_control_ = 0.0;
  double last_progress_ = 0.0;
  Eigen::Vector2d progress_anchor_ = Eigen::Vector2d::Zero();
  bool replan_now_ = true;
  bool fresh_goal_ = false;           // timers start at the first cycle after set_goal
  std::string plan_failure_;          // the global planner's last reason
  // Recovery: which behaviour runs next, why recovery began, how far the current rotation has turned.
  int recovery_index_ = 0;
  std::string recovery_trigger_;
  double rotated_ = 0.0;
  double recovery_started_ = 0.0;     // when the current recovery behaviour began, s
  double last_yaw_ = 0.0;
};

}  // namespace rfbsim::sim
