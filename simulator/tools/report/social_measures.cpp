// SPDX-License-Identifier: GPL-2.0-or-later
// social_measures: recorded samples to social_metrics' series, then the metrics.
#include "social_measures.hpp"

#include <stdexcept>
#include <string>

namespace rfbsim::report {

namespace {

Eigen::Vector2d position(const AgentState& a) { return {a.x, a.y}; }
// trajectories.csv's vx, vy is the motion over the tick before the sample, which is what SocialSample's
// velocities mean (the motion into this pose); the reader requires both columns, so nothing is estimated.
Eigen::Vector2d velocity(const AgentState& a) { return {a.vx, a.vy}; }

}  // namespace

std::vector<sim::SocialSample> social_series(const SampledSession& session) {
  std::vector<sim::SocialSample> series;
  if (!session.has_robot) return series;
  series.reserve(session.samples.size());
  for (std::size_t k = 0; k < session.samples.size(); ++k) {
    const Sample& s = session.samples[k];
    // The reader keeps ticks in order but not the time column beside them; say where it went wrong.
    if (k > 0 && s.time < session.samples[k - 1].time) {
      throw std::invalid_argument("trajectories.csv: the time at tick " + std::to_string(s.tick) +
                                  " is before the previous sample's");
    }
    if (!s.robot) {
      throw std::invalid_argument("trajectories.csv: no robot row at tick " + std::to_string(s.tick));
    }
    sim::SocialSample out;
    out.time = s.time;
    out.robot = {s.robot->x, s.robot->y, s.robot->yaw};
    out.robot_velocity = velocity(*s.robot);
    // The same people in the same order in every sample (index = identity for the intrusion episodes),
    // the avatar last, as sim::social_sample lists a live world's.
    out.people.reserve(s.people.size() + 1);
    for (std::size_t i = 0; i < s.people.size(); ++i) {
      out.people.push_back({position(s.people[i]), velocity(s.people[i]), session.person_radii.at(i)});
    }
    out.people.push_back({position(s.avatar), velocity(s.avatar), session.avatar_radius});
    series.push_back(std::move(out));
  }
  return series;
}

sim::SocialMetricsParams social_params(const SampledSession& session) {
  sim::SocialMetricsParams params;
  params.robot_radius = session.robot_radius;
  return params;
}

std::optional<sim::SocialMetrics> social_measures(const SampledSession& session) {
  if (!session.has_robot || session.samples.empty()) return std::nullopt;
  const std::vector<sim::SocialSample> series = social_series(session);
  return sim::social_metrics(series, social_params(session));
}

}  // namespace rfbsim::report
