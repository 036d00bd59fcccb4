// SPDX-License-Identifier: GPL-2.0-or-later
// NavMetrics: per-tick accumulation of the run's social-navigation measures.
#include "robot/nav_metrics.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::sim {

namespace {

}  // namespace

void NavMetrics::observe(const World& world, double dt) {
  if (!world.robot) return;
  const Robot& robot = *world.robot;
  const Eigen::Vector2d at(robot.pose.x, robot.pose.y);
  if (last_position_) sum_.path_length += (at - *last_position_).norm();
  last_position_ = at;

  // Everyone the robot should treat as a person: the pedestrians and the participant's avatar.
  std::vector<Body>& bodies = bodies_;
  bodies.clear();
  for (const Person& p : world.people) bodies.push_back({{p.pose.x, p.pose.y}, p.velocity, p.radius});
  const Avatar& a = world.avatar;
  bodies.push_back({{a.pose.x, a.pose.y},
                    a.speed * Eigen::Vector2d(std::cos(a.pose.yaw), std::sin(a.pose.yaw)), a.radius});
  touching_.resize(bodies.size(), false);

  double closest = 1e9;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const Eigen::Vector2d offset = b.position - at;
    const double distance = offset.norm();
    closest = std::min(closest, distance);
    {
      const Eigen::Vector2d toward = distance > 1e-9 ? Eigen::Vector2d(offset / distance) : Eigen::Vector2d::UnitX();
      const double robot_closing = robot.velocity.dot(toward);
      if (robot_closing > limits_.still_speed && robot_closing > -b.velocity.dot(toward)) {
        sum_.min_distance_robot_approaching = std::min(sum_.min_distance_robot_approaching, distance);
      }
    }
    const bool touching = distance - robot.radius - b.radius < limits_.collision_gap;
    if (touching && !touching_[i]) {
      // Who closed the gap: each side's speed along the line toward the other.
      const Eigen::Vector2d toward = distance > 1e-9 ? Eigen::Vector2d(offset / distance) : Eigen::Vector2d::UnitX();
      const double robot_closing = robot.velocity.dot(toward);
      const double person_closing = -b.velocity.dot(toward);
      // A robot that is not moving toward the person cannot have run into them.
      if (robot_closing > limits_.still_speed && robot_closing > person_closing) {
        ++sum_.robot_on_person;
      } else {
        ++sum_.person_on_robot;
      }
    }
    touching_[i] = touching;
  }

  ++ticks_;
  sum_.duration += dt;
  sum_.min_person_distance = std::min(sum_.min_person_distance, closest);
  closest_sum_ += std::min(closest, 1e3);
  if (closest < limits_.intimate) ++intimate_ticks_;
  if (closest < limits_.personal) ++personal_ticks_;
  if (robot.velocity.norm() < limits_.still_speed) ++still_ticks_;
}

NavSummary NavMetrics::summary() const {
  NavSummary out = sum_;
  if (ticks_ > 0) {
    const double n = static_cast<double>(ticks_);
    out.mean_closest_distance = closest_sum_ / n;
    out.intimate_fraction = static_cast<double>(intimate_ticks_) / n;
    out.personal_fraction = static_cast<double>(personal_ticks_) / n;
    out.still_fraction = static_cast<double>(still_ticks_) / n;
  }
  return out;
}

}  // namespace rfbsim::sim
