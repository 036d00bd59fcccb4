// SPDX-License-Identifier: GPL-2.0-or-later
// social_metrics: one pass over the series, tracking each person's intrusion episodes as it goes.
#include "robot/social_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rfbsim::sim {

namespace {

// One person's episode within one limit: open while inside, with its closest sample so far.
struct Episode {
  bool open = false;
  double closest = 0.0;
  bool robot_caused = false;  // at the closest sample so far
};

// Advances `episode` by one sample at centre distance `distance`; counts it when it closes (or at the end).
void track(Episode& episode, double distance, bool robot_moving_toward, double limit, double hysteresis,
           int& count, int& robot_count) {
  if (!episode.open) {
    if (distance >= limit) return;
    episode = {true, distance, robot_moving_toward};
    return;
  }
  // The first sample at the smallest distance decides who caused it.
  if (distance < episode.closest) episode = {true, distance, robot_moving_toward};
  if (distance > limit + hysteresis) {
    ++count;
    if (episode.robot_caused) ++robot_count;
    episode.open = false;
  }
}

void close(Episode& episode, int& count, int& robot_count) {
  if (!episode.open) return;
  ++count;
  if (episode.robot_caused) ++robot_count;
  episode.open = false;
}

void check_params(const SocialMetricsParams& p) {
  const auto fine = [](double x) { return std::isfinite(x) && x >= 0.0; };
  if (!fine(p.robot_radius) || !fine(p.intimate_distance) || !fine(p.personal_distance) ||
      !fine(p.episode_hysteresis) || !fine(p.still_speed) || !fine(p.ttc_horizon)) {
    throw std::invalid_argument("social metrics: radii, distances, speeds and the TTC horizon must be finite and >= 0");
  }
  if (p.personal_distance < p.intimate_distance) {
    throw std::invalid_argument("social metrics: personal_distance must be at least intimate_distance");
  }
  if (p.goal && !p.goal->allFinite()) throw std::invalid_argument("social metrics: the goal is not finite");
}

void check_sample(const SocialSample& s, std::size_t index, std::size_t people, double last_time) {
  const auto where = [&] { return "social metrics: sample " + std::to_string(index) + ": "; };
  if (!std::isfinite(s.time) || !std::isfinite(s.robot.x) || !std::isfinite(s.robot.y) ||
      !std::isfinite(s.robot.yaw) || !s.robot_velocity.allFinite()) {
    throw std::invalid_argument(where() + "the time or the robot's pose or velocity is not finite");
  }
  if (index > 0 && s.time < last_time) throw std::invalid_argument(where() + "time goes backwards");
  if (s.people.size() != people) {
    throw std::invalid_argument(where() + std::to_string(s.people.size()) + " people, the first sample had " +
                                std::to_string(people) + " (each sample must list the same people)");
  }
  for (const PersonSample& p : s.people) {
    if (!p.position.allFinite() || !p.velocity.allFinite() || !std::isfinite(p.radius) || p.radius < 0.0) {
      throw std::invalid_argument(where() + "a person's position, velocity or radius is not a finite number >= 0");
    }
  }
}

}  // namespace

double time_to_collision(const Eigen::Vector2d& offset, const Eigen::Vector2d& closing, double reach) {
  // |offset + closing t| = reach: a t^2 + b t + c = 0 with a = |closing|^2, b = 2 offset.closing,
  // c = |offset|^2 - reach^2; the earlier root, when the discs are approaching at all.
  const double c = offset.squaredNorm() - reach * reach;
  if (c <= 0.0) return 0.0;
  const double a = closing.squaredNorm();
  const double b = 2.0 * offset.dot(closing);
  if (a <= 0.0 || b >= 0.0) return SocialMetrics::kNoTime;
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return SocialMetrics::kNoTime;
  return (-b - std::sqrt(discriminant)) / (2.0 * a);
}

SocialMetrics social_metrics(std::span<const SocialSample> series, const SocialMetricsParams& params) {
  check_params(params);
  SocialMetrics out;
  if (series.empty()) return out;
  const std::size_t people = series.front().people.size();
  std::vector<Episode> personal(people), intimate(people);
  double yaw_turned = 0.0;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const SocialSample& s = series[k];
    check_sample(s, k, people, k > 0 ? series[k - 1].time : 0.0);
    const Eigen::Vector2d robot(s.robot.x, s.robot.y);

    // The robot's own motion: distance, heading turned, and time stopped (until the next sample).
    if (k > 0) {
      const SocialSample& before = series[k - 1];
      out.path_length += (robot - Eigen::Vector2d(before.robot.x, before.robot.y)).norm();
      yaw_turned += std::abs(std::remainder(s.robot.yaw - before.robot.yaw, 2.0 * std::numbers::pi));
      if (before.robot_velocity.norm() < params.still_speed) out.time_stopped += s.time - before.time;
    }

    // Each person: distances, who is approaching, time to collision, intrusion episodes.
    for (std::size_t i = 0; i < people; ++i) {
      const PersonSample& p = s.people[i];
      const Eigen::Vector2d offset = p.position - robot;
      const double distance = offset.norm();
      const double reach = params.robot_radius + p.radius;
      const Eigen::Vector2d toward = distance > 1e-12 ? Eigen::Vector2d(offset / distance) : Eigen::Vector2d::Zero();
      const bool approaching = s.robot_velocity.dot(toward) > params.still_speed;
      out.min_distance = std::min(out.min_distance, distance);
      out.min_gap = std::min(out.min_gap, distance - reach);
      if (approaching) out.min_distance_robot_approaching = std::min(out.min_distance_robot_approaching, distance);
      const double ttc = time_to_collision(offset, p.velocity - s.robot_velocity, reach);
      if (ttc <= params.ttc_horizon) {
        out.min_ttc = std::min(out.min_ttc, ttc);
        if (approaching) out.min_ttc_robot_approaching = std::min(out.min_ttc_robot_approaching, ttc);
      }
      track(personal[i], distance, approaching, params.personal_distance, params.episode_hysteresis,
            out.personal_intrusions, out.robot_personal_intrusions);
      track(intimate[i], distance, approaching, params.intimate_distance, params.episode_hysteresis,
            out.intimate_intrusions, out.robot_intimate_intrusions);
    }
  }
  // Episodes still open at the end count (the run ended inside someone's personal space).
  for (std::size_t i = 0; i < people; ++i) {
    close(personal[i], out.personal_intrusions, out.robot_personal_intrusions);
    close(intimate[i], out.intimate_intrusions, out.robot_intimate_intrusions);
  }

  out.samples = static_cast<int>(series.size());
  out.duration = series.back().time - series.front().time;
  out.rotation = yaw_turned;
  // The straight line turns once, from the start heading to the goal's bearing, and then runs straight.
  const SocialSample& first = series.front();
  const Eigen::Vector2d start(first.robot.x, first.robot.y);
  const Eigen::Vector2d goal = params.goal.value_or(Eigen::Vector2d(series.back().robot.x, series.back().robot.y));
  double needed = 0.0;
  if ((goal - start).norm() > 1e-9) {
    const double bearing = std::atan2(goal.y() - start.y(), goal.x() - start.x());
    needed = std::abs(std::remainder(bearing - first.robot.yaw, 2.0 * std::numbers::pi));
  }
  out.path_irregularity = std::max(0.0, yaw_turned - needed);
  out.path_irregularity_per_m = out.path_length > 1e-9 ? out.path_irregularity / out.path_length : 0.0;
  return out;
}

SocialSample social_sample(const World& world) {
  if (!world.robot) throw std::invalid_argument("social_sample: the world has no robot");
  SocialSample s;
  s.time = world.time;
  s.robot = world.robot->pose;
  s.robot_velocity = world.robot->velocity;
  s.people.reserve(world.people.size() + 1);
  for (const Person& p : world.people) s.people.push_back({{p.pose.x, p.pose.y}, p.velocity, p.radius});
  const Avatar& a = world.avatar;
  s.people.push_back({{a.pose.x, a.pose.y}, a.speed * Eigen::Vector2d(std::cos(a.pose.yaw), std::sin(a.pose.yaw)),
                      a.radius});
  return s;
}

}  // namespace rfbsim::sim
