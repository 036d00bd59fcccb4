// SPDX-License-Identifier: GPL-2.0-or-later
// RobotMetrics: the recorded samples replayed through NavMetrics, plus the kinematic measures.
#include "robot_metrics.hpp"

#include <algorithm>
#include <cmath>

#include "robot/nav_metrics.hpp"
#include "robot/sensing/motion_delta.hpp"
#include "world/world.hpp"

namespace rfbsim::report {

namespace {

// A world that holds just what NavMetrics reads, filled from one sample: the robot, the people and the
// avatar, each with its position, velocity and body radius.
class SampleWorld {
 public:
  explicit SampleWorld(const SampledSession& session) {
    world_.robot.emplace();
    world_.robot->radius = session.robot_radius;
    world_.avatar.radius = session.avatar_radius;
    world_.people.resize(session.person_ids.size());
    for (std::size_t i = 0; i < world_.people.size(); ++i) {
      world_.people[i].id = session.person_ids[i];
      world_.people[i].radius = session.person_radii[i];
    }
  }

  const sim::World& at(const Sample& sample) {
    const AgentState& r = *sample.robot;
    world_.robot->pose = {r.x, r.y, r.yaw};
    world_.robot->velocity = {r.vx, r.vy};
    // The world keeps the avatar's velocity as a signed speed along its heading; the recorded vector is
    // the same thing, so heading along it and speed as its length give NavMetrics the recorded velocity.
    const AgentState& a = sample.avatar;
    world_.avatar.pose = {a.x, a.y, std::atan2(a.vy, a.vx)};
    world_.avatar.speed = std::hypot(a.vx, a.vy);
    for (std::size_t i = 0; i < world_.people.size(); ++i) {
      const AgentState& p = sample.people[i];
      world_.people[i].pose = {p.x, p.y, p.yaw};
      world_.people[i].velocity = {p.vx, p.vy};
    }
    world_.tick = sample.tick;
    world_.time = sample.time;
    return world_;
  }

 private:
  sim::World world_;
};

// Mean length of the k-th finite difference of the robot's velocity over the sample spacing (k = 1:
// acceleration, k = 2: jerk); none with fewer than k + 1 samples.
std::optional<double> mean_difference_norm(const std::vector<Sample>& samples, int order) {
  std::vector<Eigen::Vector2d> series;
  std::vector<double> times;
  for (const Sample& s : samples) {
    series.emplace_back(s.robot->vx, s.robot->vy);
    times.push_back(s.time);
  }
  for (int k = 0; k < order; ++k) {
    // Each difference stands at the midpoint of the two values it came from.
    std::vector<Eigen::Vector2d> next;
    std::vector<double> next_times;
    for (std::size_t i = 0; i + 1 < series.size(); ++i) {
      const double dt = times[i + 1] - times[i];
      if (!(dt > 0.0)) continue;  // a repeated time cannot be differenced
      next.push_back((series[i + 1] - series[i]) / dt);
      next_times.push_back(0.5 * (times[i] + times[i + 1]));
    }
    series = std::move(next);
    times = std::move(next_times);
  }
  if (series.empty()) return std::nullopt;
  double sum = 0.0;
  for (const Eigen::Vector2d& v : series) sum += v.norm();
  return sum / static_cast<double>(series.size());
}

}  // namespace

std::optional<RobotMetrics> robot_metrics(const SampledSession& session) {
  if (!session.has_robot || session.samples.empty()) return std::nullopt;

  // NavMetrics measures path, distances, the two inner zones, collisions and standing still. A second
  // one whose inner limit is the social zone's outer edge counts the samples inside the social zone,
  // rather than repeating its closest-person search here.
  sim::NavMetrics nav;
  sim::ZoneLimits social_limits;
  social_limits.intimate = kSocialZoneLimit;
  social_limits.personal = kSocialZoneLimit;
  sim::NavMetrics social(social_limits);
  SampleWorld world(session);
  RobotMetrics out;
  double speed_sum = 0.0;
  for (std::size_t i = 0; i < session.samples.size(); ++i) {
    const Sample& sample = session.samples[i];
    const sim::World& w = world.at(sample);
    nav.observe(w, session.sample_interval);
    social.observe(w, session.sample_interval);
    speed_sum += std::hypot(sample.robot->vx, sample.robot->vy);
    if (i > 0) out.heading_change += std::abs(sim::normalize_angle(sample.robot->yaw - session.samples[i - 1].robot->yaw));
  }
  const sim::NavSummary s = nav.summary();
  const double n = static_cast<double>(session.samples.size());

  out.path_length = s.path_length;
  const AgentState& first = *session.samples.front().robot;
  const AgentState& last = *session.samples.back().robot;
  const double straight = std::hypot(last.x - first.x, last.y - first.y);
  if (straight >= 0.1) out.path_ratio = s.path_length / straight;
  out.min_person_distance = s.min_person_distance;
  out.mean_closest_distance = s.mean_closest_distance;
  if (s.min_distance_robot_approaching < 1e9) out.min_distance_robot_approaching = s.min_distance_robot_approaching;
  const double within_social = social.summary().intimate_fraction;
  // Each fraction is a count over the same n, so the differences are exact but for rounding below zero.
  const auto percent = [](double fraction) { return std::max(0.0, 100.0 * fraction); };
  out.pct_intimate = percent(s.intimate_fraction);
  out.pct_personal = percent(s.personal_fraction - s.intimate_fraction);
  out.pct_social = percent(within_social - s.personal_fraction);
  out.pct_public = percent(1.0 - within_social);
  out.robot_on_person = s.robot_on_person;
  out.person_on_robot = s.person_on_robot;
  out.time_not_moving = s.still_fraction * n * session.sample_interval;
  out.mean_speed = speed_sum / n;
  out.mean_abs_acceleration = mean_difference_norm(session.samples, 1);
  out.mean_abs_jerk = mean_difference_norm(session.samples, 2);
  return out;
}

}  // namespace rfbsim::report
