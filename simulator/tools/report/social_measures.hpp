// SPDX-License-Identifier: GPL-2.0-or-later
// The robot's social-navigation measures over a recorded session (simulator/robot/social_metrics.hpp: the
// robot's own approaches, who caused each personal-space intrusion, time to collision, path irregularity,
// time stopped): the session's samples turned into social_metrics' series, so that sim_report gives the
// numbers bench_nav gives for the same motion.
#pragma once

#include <optional>
#include <vector>

#include "robot/social_metrics.hpp"
#include "session_samples.hpp"

namespace rfbsim::report {

/// social_metrics' series of `session`: one SocialSample per sample, its people in session.json's order and
/// the participant's avatar last (as sim::social_sample orders a world), every body with the radius
/// session.json gives it and the velocity trajectories.csv recorded. Empty without a robot. Throws
/// std::invalid_argument naming the tick when a sample's time is before the previous one's (a damaged file).
std::vector<sim::SocialSample> social_series(const SampledSession& session);

/// The thresholds for `session`: social_metrics' defaults (docs/sources.md) with session.json's robot
/// radius. No goal: the straight line of path irregularity ends where the robot's last sample is.
sim::SocialMetricsParams social_params(const SampledSession& session);

/// sim::social_metrics over `session`'s samples; none without a robot or without samples. Throws as
/// social_series does.
std::optional<sim::SocialMetrics> social_measures(const SampledSession& session);

}  // namespace rfbsim::report
