// SPDX-License-Identifier: GPL-2.0-or-later
// Social-navigation metrics of one robot run, computed after the fact from a time series of the robot's
// pose and velocity and the people's positions and velocities: pure functions, no world, no state, so that
// bench_nav, the tests and sim_report (from trajectories.csv) compute the same numbers the same way.
//
// Definitions, and where they come from (docs/performance.md, "Navigation: bench_nav", lists them too):
//  - Minimum distance to people (centre to centre, and surface gap): Gao & Huang 2022, "Evaluation of
//    socially-aware robot navigation" (Front. Robot. AI 8:721317), which surveys it as the commonest measure.
//  - Personal-space and intimate-space intrusions: SEAN 2.0 (Tsoi et al. 2022) / SEANavBench's "robot on
//    person personal distance violation", "intimate distance violation": how many times the robot comes
//    within Hall's personal (1.2 m) or intimate (0.45 m) distance of a person. Counted here as episodes: an
//    episode with one person starts when the centre distance drops below the limit and ends once it is back
//    above limit + hysteresis (so a person walking along the boundary is one intrusion, not fifty).
//  - Who caused it (rfbsim's rule, after SEANavBench's robot-on-person / person-on-robot split): an episode
//    is robot-caused when, at its closest approach (the first sample at the episode's smallest distance),
//    the robot's velocity has a component toward the person above still_speed. At that sample the velocity
//    is the motion that brought the robot there, so a robot that drove up to a person and stopped is
//    counted, and a person walking up to a standing robot is not.
//  - Minimum distance while approaching: the smallest centre distance at a sample where the robot's velocity
//    has a component toward that person above still_speed: how near the robot itself chose to go.
//  - Time to collision (constant velocity; Gao & Huang 2022, "time to collision"): the time until the two
//    discs would touch if both kept their velocity; 0 when they already touch; none beyond ttc_horizon.
//  - Path irregularity (Guzzi et al. 2013, "Human-friendly robot navigation in dynamic environments", also in
//    Kivrak et al. 2021 and SEANavBench): the total rotation of the robot's heading beyond what the straight
//    line needs (turning once from the start heading to face the goal), in rad and per metre travelled.
//  - Time stopped (docs/sources.md; SEANavBench "time not moving"): time with the robot slower than still_speed.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "world/world.hpp"

namespace rfbsim::sim {

/// One person at one instant.
struct PersonSample {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< m, world frame (centre)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, world frame
  double radius = 0.25;                                ///< m, body radius
};

/// The robot and the people at one instant. `people` must list the same people in the same order in every
/// sample of a series (index = identity); the episodes are tracked per index.
struct SocialSample {
  double time = 0.0;                                         ///< s
  Pose2 robot;                                               ///< m, m, rad
  Eigen::Vector2d robot_velocity = Eigen::Vector2d::Zero();  ///< m/s, world frame: the motion into this pose
  std::vector<PersonSample> people;
};

/// The thresholds of the metrics (defaults: docs/sources.md's Hall zones and "time not moving").
struct SocialMetricsParams {
  double robot_radius = 0.16;        ///< m, for the surface gap and time to collision (Kuri)
  double intimate_distance = 0.45;   ///< m centre to centre (as the SEAN-EP paper's logs gave it)
  double personal_distance = 1.2;    ///< m centre to centre
  double episode_hysteresis = 0.05;  ///< m beyond the limit before an intrusion episode ends
  double still_speed = 0.01;         ///< m/s: slower is stopped, and no approach
  double ttc_horizon = 10.0;         ///< s: a collision further ahead than this does not count
  /// m: where the straight line of path irregularity goes; none: the last sample's position.
  std::optional<Eigen::Vector2d> goal;
};

/// The numbers of one run. Distances with nobody around stay at kNoDistance, times at kNoTime.
struct SocialMetrics {
  static constexpr double kNoDistance = 1e9;
  static constexpr double kNoTime = 1e9;
  int samples = 0;
  double duration = 0.0;      ///< s from the first sample to the last
  double path_length = 0.0;   ///< m the robot travelled
  double time_stopped = 0.0;  ///< s with the robot slower than still_speed (sample to next sample)
  double min_distance = kNoDistance;  ///< m, closest centre distance to any person
  double min_gap = kNoDistance;       ///< m, closest surface gap (centre distance minus both radii)
  double min_distance_robot_approaching = kNoDistance;  ///< m, closest while the robot moved toward them
  int personal_intrusions = 0;        ///< episodes within personal_distance, anyone's doing
  int robot_personal_intrusions = 0;  ///< of those, robot-caused
  int intimate_intrusions = 0;        ///< episodes within intimate_distance
  int robot_intimate_intrusions = 0;  ///< of those, robot-caused
  double min_ttc = kNoTime;                   ///< s, smallest constant-velocity time to collision
  double min_ttc_robot_approaching = kNoTime; ///< s, the same while the robot moved toward that person
  double rotation = 0.0;                  ///< rad the heading turned in all
  double path_irregularity = 0.0;         ///< rad turned beyond the straight line's one turn (>= 0)
  double path_irregularity_per_m = 0.0;   ///< rad/m: path_irregularity / path_length (0 if it never moved)

  /// The robot's share of the personal-space intrusions (0..1; 0 when there were none).
  [[nodiscard]] double robot_intrusion_share() const {
    return personal_intrusions > 0 ? static_cast<double>(robot_personal_intrusions) / personal_intrusions : 0.0;
  }
};

/// The metrics of `series` (samples in time order). Throws std::invalid_argument naming the problem for a
/// sample out of time order, a sample whose people count differs from the first's, non-finite values or
/// thresholds that make no sense (personal_distance < intimate_distance, negative radii or times). An empty
/// series gives the zero metrics.
SocialMetrics social_metrics(std::span<const SocialSample> series, const SocialMetricsParams& params = {});

/// The constant-velocity time (s) until two discs touch: `offset` = other centre - own centre (m),
/// `closing` = other velocity - own velocity (m/s), `reach` = the sum of the radii (m). 0 when they already
/// touch; kNoTime when they never will.
double time_to_collision(const Eigen::Vector2d& offset, const Eigen::Vector2d& closing, double reach);

/// The sample of `world` now: the robot (which must exist) and every person, the participant's avatar last.
SocialSample social_sample(const World& world);

}  // namespace rfbsim::sim
