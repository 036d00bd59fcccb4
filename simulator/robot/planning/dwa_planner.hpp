// SPDX-License-Identifier: GPL-2.0-or-later
// DwaPlanner: the robot's local planner in the style of ROS dwa_local_planner: sample (v, w) in the dynamic
// window, simulate each for sim_time on the local costmap, let the critics score them, command the best.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>
#include <cstdint>
#include <string>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"
#include "robot/planning/distance_grid.hpp"
#include "robot/planning/dwa_critics.hpp"
#include "robot/planning/dwa_people_critic.hpp"
#include "robot/planning/dwa_params.hpp"
#include "robot/planning/dwa_rollout.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What the local planner commands for the next control period.
struct DwaCommand {
  bool found = false;  ///< whether a legal command was found; false: v = w = 0 and `reason` says why
  double v = 0.0;      ///< m/s forward
  double w = 0.0;      ///< rad/s counter-clockwise
  std::vector<Eigen::Vector2d> trajectory;  ///< world points (m) of the chosen rollout, now to sim_time
  double score = 0.0;  ///< its weighted cost (lower is better)
  std::string reason;  ///< why found is false; empty otherwise
  int rollouts = 0;    ///< rollouts simulated this cycle
};

/// The DWA local planner. Owns the global path it follows and its scratch buffers (nothing is allocated
/// per cycle once they have grown). Not thread-safe: one planner per robot.
class DwaPlanner {
 public:
  explicit DwaPlanner(DwaParams params = {});

  /// Sets the global path to follow (world points, m, start to goal) and forgets the oscillation flags
  /// and the progress along the old one. A path with a non-finite point is refused: compute() then says so.
  /// The people the robot sees this cycle (for the people critic); empty switches that critic off.
  void set_people(std::span<const SeenPerson> people) { people_.set_people(people); }
  void set_plan(std::vector<Eigen::Vector2d> global_path);

  /// The command for the robot at `pose` (the localization estimate) moving at v (m/s) and w (rad/s), on
  /// `local`, a rolling costmap window around it. The path is followed from its point nearest the robot
  /// onward, as far as it stays on `local`; that stretch's end is the local goal. Samples the window
  /// (vx_samples x vth_samples, plus 0 rad/s and the sample braking along the current arc), rolls each out
  /// and lets the critics score it: oscillation, obstacle (occdist_scale), path distance and alignment
  /// (path_distance_bias), goal distance and goal front (goal_distance_bias); the lowest total wins, ties
  /// going to the faster, then straighter, then left-turning sample. Stopping at the goal is the caller's
  /// job (within_xy_tolerance). Never throws for bad input: found = false with a reason.
  DwaCommand compute(const CostmapGrid& local, const Pose2& pose, double v, double w);

  /// A turn in place toward `target_yaw` (rad) for a robot turning at w (rad/s): as fast as max_vel_theta
  /// and the need to stop on the heading allow, within acc_lim_theta of w. Turning in place moves no part
  /// of a round robot, so only a robot whose own cell is lethal, unknown or off `local` is refused.
  [[nodiscard]] DwaCommand rotate_toward(const CostmapGrid& local, const Pose2& pose, double w, double target_yaw) const;

  [[nodiscard]] const DwaParams& params() const { return params_; }
  /// The path being followed.
  [[nodiscard]] const std::vector<Eigen::Vector2d>& plan() const { return plan_; }
  /// The local goal (m) of the last compute() that got as far as cutting the path.
  [[nodiscard]] const Eigen::Vector2d& local_goal() const { return local_goal_; }
  /// Distances to the path over the last compute()'s local costmap (for tests and debug overlays).
  [[nodiscard]] const DistanceGrid& path_map() const { return path_map_; }

 private:
  static constexpr std::size_t kCritics = 7;
  DwaCommand fail(std::string reason) const;
  // Fills this cycle's distance maps (to the path, the local goal, the goal front); returns the goal-front
  // map to score with.
  const DistanceGrid* build_maps(const CostmapGrid& local, const Eigen::Vector2d& robot);
  // Why no rollout was legal, naming the critics that rejected them and how many each.
  std::string rejection_reason(int rollouts, const std::array<int, kCritics>& rejected);

  DwaParams params_;
  std::string params_error_;  // non-empty when params_ cannot work
  std::vector<Eigen::Vector2d> plan_;
  std::string plan_error_;
  std::size_t progress_ = 0;  // index of the path point nearest the robot last cycle
  Eigen::Vector2d local_goal_ = Eigen::Vector2d::Zero();

  // Per-cycle scratch, kept for its capacity.
  std::vector<std::int32_t> path_cells_;
  std::vector<std::int32_t> goal_cells_;
  DistanceGrid path_map_;
  DistanceGrid goal_map_;
  DistanceGrid goal_front_map_;
  std::vector<double> v_samples_;
  std::vector<double> w_samples_;
  Rollout candidate_;
  Rollout best_;

  // The critics, in the order they score (cheap and often-rejecting first, as in ROS).
  OscillationCritic oscillation_;
  ObstacleCritic obstacle_;
  PeopleCritic people_;
  MapDistanceCritic path_;
  MapDistanceCritic goal_;
  MapDistanceCritic alignment_;
  MapDistanceCritic goal_front_;
  std::array<double, kCritics> weights_{};  // per critic, in critics() order
  // The critics in scoring order (built on demand so that a copied planner points at its own).
  std::array<DwaCritic*, kCritics> critics() {
    return {&oscillation_, &obstacle_, &people_, &path_, &goal_, &alignment_, &goal_front_};
  }
};

/// Why a DWA parameter set cannot work ("bad DWA parameters: need finite min_vel_x <= max_vel_x"), or empty.
std::string dwa_params_error(const DwaParams& params);

/// Whether `pose` is within `xy_goal_tolerance` (m) of `goal`; false for non-finite input.
bool within_xy_tolerance(const Pose2& pose, const Eigen::Vector2d& goal, double xy_goal_tolerance);

}  // namespace rfbsim::sim
