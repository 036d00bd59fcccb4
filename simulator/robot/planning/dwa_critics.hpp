// SPDX-License-Identifier: GPL-2.0-or-later
// DWA critics: each rates every rollout of a control cycle. prepare() once per cycle, then score(): a cost
// >= 0, or negative when the rollout is illegal; the planner applies the weights and stops early (STYLE.md 7).
#pragma once

#include <Eigen/Core>

#include "robot/costmap/costmap_grid.hpp"
#include "robot/planning/distance_grid.hpp"
#include "robot/planning/dwa_rollout.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What the critics may read during one control cycle; owned by the planner, valid until its next cycle.
struct DwaScene {
  const CostmapGrid* grid = nullptr;            ///< the local costmap
  Pose2 pose;                                   ///< the robot now
  Eigen::Vector2d local_goal = Eigen::Vector2d::Zero();  ///< m: the last global-path point on the grid
  const DistanceGrid* path_map = nullptr;       ///< distances to the global path's cells on the grid
  const DistanceGrid* goal_map = nullptr;       ///< distances to the local goal's cell
  const DistanceGrid* goal_front_map = nullptr; ///< distances to the local goal pushed one nose length on
};

/// A rollout critic.
class DwaCritic {
 public:
  virtual ~DwaCritic() = default;
  /// Short name for reasons and debugging ("obstacle").
  [[nodiscard]] virtual const char* name() const = 0;
  /// What the rollouts it rejects do, for reasons ("hit obstacles or leave the local costmap").
  [[nodiscard]] virtual const char* rejection() const = 0;
  /// Reads the cycle's scene; false switches the critic off for this cycle (it then neither scores nor rejects).
  virtual bool prepare(const DwaScene& scene) = 0;
  /// The rollout's cost (>= 0; units are the critic's own), or negative if the rollout is illegal.
  [[nodiscard]] virtual double score(const Rollout& rollout) const = 0;
};

/// ROS's ObstacleCostFunction: the highest cell cost along the rollout (0..252); illegal if it passes
/// through an inscribed, lethal or unknown cell or off the costmap up to sim_time + stop_time_buffer. Every
/// cell the straight pieces between its points cross counts, not only the points' cells (ROS's), so that no
/// rollout grazes the corner of an inscribed cell. A robot whose own cell is inscribed (pushed into
/// inflation) may drive out: the rollout may cross inscribed cells until its first cheaper one, and must be
/// out by sim_time.
class ObstacleCritic final : public DwaCritic {
 public:
  [[nodiscard]] const char* name() const override { return "obstacle"; }
  [[nodiscard]] const char* rejection() const override { return "hit obstacles or leave the local costmap"; }
  bool prepare(const DwaScene& scene) override;
  [[nodiscard]] double score(const Rollout& rollout) const override;

 private:
  const CostmapGrid* grid_ = nullptr;
  bool start_inscribed_ = false;
  bool start_blocked_ = false;  // the robot's own cell is lethal, unknown or off the grid: nothing is legal
};

/// ROS's MapGridCostFunction: the distance (m) from a point of the rollout's end pose, `shift` m ahead
/// along its heading, to the targets of one distance map. Illegal if the end itself cannot reach them; a
/// shifted "nose" point that is unreachable (over an obstacle, off the grid) reads the end's distance plus
/// `shift`, as if the nose pointed straight away (ROS rejects such rollouts; a nose over inflation is no
/// collision). `off_near_goal` switches it off within `shift` of the local goal, as ROS's alignment cost is.
class MapDistanceCritic final : public DwaCritic {
 public:
  /// Which of the scene's distance maps it reads.
  enum class Target { Path, Goal, GoalFront };
  /// `name` must outlive the critic (a literal); `shift` in m.
  MapDistanceCritic(const char* name, Target target, double shift, bool off_near_goal)
      : name_(name), target_(target), shift_(shift), off_near_goal_(off_near_goal) {}
  [[nodiscard]] const char* name() const override { return name_; }
  [[nodiscard]] const char* rejection() const override {
    return target_ == Target::Path ? "end where the global path cannot be reached" : "end where the local goal cannot be reached";
  }
  bool prepare(const DwaScene& scene) override;
  [[nodiscard]] double score(const Rollout& rollout) const override;

 private:
  const char* name_;
  Target target_;
  double shift_;
  bool off_near_goal_;
  const CostmapGrid* grid_ = nullptr;
  const DistanceGrid* map_ = nullptr;
};

/// ROS's OscillationCostFunction: once the robot has chosen to turn in place (or drive) one way and then the
/// other, the first way is illegal until it has moved oscillation_reset_dist or turned oscillation_reset_angle.
class OscillationCritic final : public DwaCritic {
 public:
  /// reset_dist in m, reset_angle in rad; commands slower than min_vel_trans (m/s) count as turning in place.
  OscillationCritic(double reset_dist, double reset_angle, double min_vel_trans)
      : reset_dist_(reset_dist), reset_angle_(reset_angle), min_vel_trans_(min_vel_trans) {}
  [[nodiscard]] const char* name() const override { return "oscillation"; }
  [[nodiscard]] const char* rejection() const override { return "would reverse a recent turn or drive (oscillation)"; }
  bool prepare(const DwaScene&) override { return true; }
  [[nodiscard]] double score(const Rollout& rollout) const override;
  /// Records the command chosen at `pose` (sets flags when it reverses a direction), then clears the flags
  /// if the robot has moved or turned far enough since the last flag was set.
  void update(const Pose2& pose, double v, double w);
  /// Forgets every flag (a new plan).
  void reset();

 private:
  double reset_dist_;
  double reset_angle_;
  double min_vel_trans_;
  // Seen going forward / backward / turning left / right since the last reset, and the "only" flags that
  // forbid the opposite once a reversal happened.
  bool forward_ = false, backward_ = false, forward_only_ = false, backward_only_ = false;
  bool left_ = false, right_ = false, left_only_ = false, right_only_ = false;
  Pose2 flagged_at_;  // where the last flag was set
};

}  // namespace rfbsim::sim
