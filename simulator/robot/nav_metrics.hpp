// SPDX-License-Identifier: GPL-2.0-or-later
// NavMetrics: the social-navigation measures of one robot run (docs/sources.md, Social navigation metrics),
// accumulated tick by tick from the world: path length, closest approach to people, time in Hall's zones,
// and collisions split by who moved into whom. Used by the tests, bench_nav and (later) session reports.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "world/world.hpp"

namespace rfbsim::sim {

/// Hall's zones by distance between the robot's and a person's centres, and what counts as a collision.
struct ZoneLimits {
  double intimate = 0.45;       ///< m
  double personal = 1.2;        ///< m
  double collision_gap = 0.02;  ///< m between the bodies' surfaces: closer is a collision
  double still_speed = 0.01;    ///< m/s: slower counts as not moving
};

/// The measures of one run (docs/sources.md, Social navigation metrics).
struct NavSummary {
  double duration = 0.0;            ///< s observed
  double path_length = 0.0;         ///< m the robot travelled
  double min_person_distance = 1e9; ///< m, closest centre distance to any person (the avatar included)
  double mean_closest_distance = 0.0;  ///< m, the closest person's distance averaged over ticks
  /// m, the closest centre distance to a person at a tick when the robot was the one closing in (moving
  /// toward them faster than they toward it): how near the robot itself chose to go. People walking up to
  /// a robot (pedestrians stop 5 cm short of any body) count in min_person_distance but not here.
  double min_distance_robot_approaching = 1e9;
  double intimate_fraction = 0.0;   ///< of ticks with someone within the intimate limit
  double personal_fraction = 0.0;   ///< of ticks with someone within the personal limit (intimate included)
  double still_fraction = 0.0;      ///< of ticks with the robot slower than still_speed
  int robot_on_person = 0;          ///< collisions begun while the robot moved toward the person faster
  int person_on_robot = 0;          ///< collisions begun while the person moved toward the robot faster
};

/// Accumulates NavSummary from the world, tick by tick.
class NavMetrics {
 public:
  explicit NavMetrics(ZoneLimits limits = {}) : limits_(limits) {}
  /// Takes one tick of the world after it was stepped (dt s long). No-op without a robot.
  void observe(const World& world, double dt);
  [[nodiscard]] NavSummary summary() const;

 private:
  ZoneLimits limits_;
  NavSummary sum_;
  std::size_t ticks_ = 0, intimate_ticks_ = 0, personal_ticks_ = 0, still_ticks_ = 0;
  double closest_sum_ = 0.0;
  std::optional<Eigen::Vector2d> last_position_;
  std::vector<bool> touching_;  // per person (avatar last): in a collision at the last tick
  struct Body {
    Eigen::Vector2d position;
    Eigen::Vector2d velocity;
    double radius;
  };
  std::vector<Body> bodies_;  // this tick's people and avatar, reused
};

}  // namespace rfbsim::sim
