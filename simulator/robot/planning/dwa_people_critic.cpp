// SPDX-License-Identifier: GPL-2.0-or-later
// PeopleCritic: constant-velocity prediction of the people in view along each rollout.
#include "robot/planning/dwa_people_critic.hpp"

#include <algorithm>

namespace rfbsim::sim {

bool PeopleCritic::prepare(const DwaScene& /*scene*/) { return !people_.empty() && horizon_ > 0.0; }

double PeopleCritic::score(const Rollout& rollout) const {
  if (rollout.poses.empty() || rollout.end == 0) return 0.0;
  const double dt = sim_time_ / static_cast<double>(rollout.end);  // s between the rollout's points
  const Eigen::Vector2d start(rollout.poses[0].x, rollout.poses[0].y);
  for (const SeenPerson& person : people_) {
    const double reach = robot_radius_ + person.radius + clearance_;
    const bool walking = personal_clearance_ > 0.0 && person.velocity.norm() >= walking_speed_;
    const double personal_reach = robot_radius_ + person.radius + personal_clearance_;
    const double gap_now = (person.position - start).norm();
    // A walker already within personal space: the first step must not close in on where they are now either
    // (prediction alone would let the robot creep toward someone about to leave that spot).
    if (walking && gap_now < personal_reach && rollout.end >= 1 && rollout.poses.size() > 1) {
      const Eigen::Vector2d first(rollout.poses[1].x, rollout.poses[1].y);
      if ((person.position - first).norm() < gap_now - 1e-9) return -1.0;
    }
    double last = gap_now;
    for (std::size_t i = 1; i <= rollout.end && i < rollout.poses.size(); ++i) {
      const double t = dt * static_cast<double>(i);
      if (t > horizon_) break;
      const Eigen::Vector2d ahead = person.position + t * person.velocity;
      const Eigen::Vector2d at(rollout.poses[i].x, rollout.poses[i].y);
      const double gap = (ahead - at).norm();
      // Too close and closing in: illegal. Already too close but opening up: the way out stays allowed.
      if (gap < reach && gap < last - 1e-9) return -1.0;
      // Near a walker, the robot's own step (the person held where they will be) must not close in.
      if (walking && gap < personal_reach) {
        const Eigen::Vector2d before(rollout.poses[i - 1].x, rollout.poses[i - 1].y);
        if (gap < (ahead - before).norm() - 1e-9) return -1.0;
      }
      last = gap;
    }
  }
  return 0.0;
}

}  // namespace rfbsim::sim
