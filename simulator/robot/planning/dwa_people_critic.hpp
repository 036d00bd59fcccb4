// SPDX-License-Identifier: GPL-2.0-or-later
// PeopleCritic (rfbsim; ROS's DWA has none): the costmap shows where people were at the last scan, but a
// person crossing the robot's way moves 0.13 m between two control cycles. This critic predicts each person
// the robot sees at constant velocity over the first `people_horizon` seconds of every rollout and rejects a
// rollout that would bring the two bodies closer than `people_clearance`; one that moves away from someone
// already that close stays legal, so the robot can always back out of a squeeze.
#pragma once

#include <span>
#include <vector>

#include "robot/costmap/seen_person.hpp"
#include "robot/planning/dwa_critics.hpp"

namespace rfbsim::sim {

class PeopleCritic final : public DwaCritic {
 public:
  /// `robot_radius` m; `clearance` m between the bodies' surfaces; `horizon` s of prediction; `sim_time` s
  /// that a rollout's points up to its `end` span.
  PeopleCritic(double robot_radius, double clearance, double horizon, double sim_time)
      : robot_radius_(robot_radius), clearance_(clearance), horizon_(horizon), sim_time_(sim_time) {}

  [[nodiscard]] const char* name() const override { return "people"; }
  [[nodiscard]] const char* rejection() const override { return "come too close to a person"; }
  bool prepare(const DwaScene& scene) override;
  [[nodiscard]] double score(const Rollout& rollout) const override;
  /// The people seen this cycle (positions and velocities in the costmap's frame).
  void set_people(std::span<const SeenPerson> people) { people_.assign(people.begin(), people.end()); }

 private:
  double robot_radius_;
  double clearance_;
  double horizon_;
  double sim_time_;
  std::vector<SeenPerson> people_;
};

}  // namespace rfbsim::sim
