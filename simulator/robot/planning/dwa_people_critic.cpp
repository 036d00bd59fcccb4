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
    const double gap_now = (person.position - start).norm();
    double last = gap_now;
    for (std::size_t i = 1; i <= rollout.end && i < rollout.poses.size(); ++i) {
      const double t = dt * static_cast<double>(i);
      if (t > horizon_) break;
      const Eigen::Vector2d ahead = person.position + t * person.velocity;
      const double gap = (ahead - Eigen::Vector2d(rollout.poses[i].x, rollout.poses[i].y)).norm();
      // Too close and closing in: illegal. Already too close but opening up: the way out stays allowed.
      if (gap < reach && gap < last - 1e-9) return -1.0;
      last = gap;
    }
  }
  return 0.0;
}

}  // namespace rfbsim::sim
