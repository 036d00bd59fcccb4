// SPDX-License-Identifier: GPL-2.0-or-later
// PeopleCritic (rfbsim; ROS's DWA has none): the costmap shows where people were at the last scan, but a
// person crossing the robot's way moves 0.13 m between two control cycles. This critic predicts each person
// the robot sees at constant velocity over the first `people_horizon` seconds of every rollout and rejects a
// rollout that would bring the two bodies closer than `people_clearance`; one that moves away from someone
// already that close stays legal, so the robot can always back out of a squeeze. A second, wider rule keeps
// the robot from closing in on people who walk (issue 19): within `personal_clearance` of a walking person's
// predicted position, a rollout point that the robot's own step brings nearer that position is illegal, so
// the robot stops, turns or moves aside while a walker passes close, and never drives up to them itself.
#pragma once

#include <span>
#include <vector>

#include "robot/costmap/seen_person.hpp"
#include "robot/planning/dwa_critics.hpp"

namespace rfbsim::sim {

class PeopleCritic final : public DwaCritic {
 public:
  /// `robot_radius` m; `clearance` m between the bodies' surfaces; `horizon` s of prediction; `sim_time` s
  /// that a rollout's points up to its `end` span; `personal_clearance` m between the bodies within which
  /// the robot may not close in on a person walking at least `walking_speed` m/s (0: no such rule).
  PeopleCritic(double robot_radius, double clearance, double horizon, double sim_time, double personal_clearance = 0.0,
               double walking_speed = 0.5)
      : robot_radius_(robot_radius), clearance_(clearance), horizon_(horizon), sim_time_(sim_time),
        personal_clearance_(personal_clearance), walking_speed_(walking_speed) {}

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
  double personal_clearance_;
  double walking_speed_;
  std::vector<SeenPerson> people_;
};

}  // namespace rfbsim::sim
