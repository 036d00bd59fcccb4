// SPDX-License-Identifier: GPL-2.0-or-later
// The social force model: the accelerations that steer one pedestrian toward its waypoint and away from
// other people and from walls. Pure functions of positions and velocities; the crowd sums and integrates them.
//
// Two pedestrian-interaction models are available (SocialForceParams::model):
//  - Moussaid2009 (the default): M. Moussaid, D. Helbing, S. Garnier, A. Johansson, M. Combe, G. Theraulaz,
//    "Experimental study of the behavioural mechanisms underlying self-organization in human crowds",
//    Proc. R. Soc. B 276 (2009), as implemented by PySocialForce's SocialForce, pedsim and lightsfm.
//    Its angular term turns people aside before they meet, so head-on pairs pass; it is what PySocialForce
//    runs by default.
//  - HelbingMolnar1995: D. Helbing, P. Molnar, "Social force model for pedestrian dynamics", Phys. Rev. E 51
//    (1995) 4282, with the elliptical potential of eq. (4) and the field of view of eq. (7). Its force acts
//    along the line between two people, so two people meeting exactly head-on stop in front of each other
//    (our head-on test shows it); kept for comparison.
// The goal force (eq. 2), the wall force (eq. 5) and the speed cap (eq. 9) are Helbing & Molnar's in both.
#pragma once

#include <Eigen/Core>

#include "map/distance_field.hpp"

namespace rfbsim::sim {

/// Which pedestrian-pedestrian interaction to use.
enum class PedestrianModel {
  Moussaid2009,       ///< velocity-dependent, with an angular (side-stepping) term
  HelbingMolnar1995,  ///< elliptical potential V0 exp(-b / sigma), with field of view
};

/// The model's parameters. Sources: PySocialForce (Y. Gao, pysocialforce/utils/default.toml, defaults taken
/// from the papers), the papers above, and rfbsim choices where marked.
struct SocialForceParams {
  PedestrianModel model = PedestrianModel::Moussaid2009;

  // Goal force (v0 e - v) / tau: Helbing & Molnar eq. (2); tau 0.5 s in PySocialForce [desired_force].
  double relaxation_time = 0.5;  ///< tau, s

  // Moussaid 2009, PySocialForce [social_force]: lambda 2.0, gamma 0.35, n 2, n' 3, factor 5.1.
  double social_factor = 5.1;      ///< A, m/s^2: strength of the pedestrian interaction
  double lambda_importance = 2.0;  ///< weight of the relative velocity against the relative direction
  double gamma = 0.35;             ///< B = gamma |D|: interaction range per unit of |D|, m
  double n = 2.0;                  ///< angular interaction's narrowness (side-step term), 1/rad
  double n_prime = 3.0;            ///< speed interaction's narrowness (braking term), 1/rad

  // Helbing & Molnar 1995, PySocialForce [ped_repulsive_force]: V0 2.1, sigma 0.3, field of view
  // 2 * 100 deg with weight 0.5 outside; Delta t 2 s is the paper's (section III).
  double v0 = 2.1;                ///< V0, m^2/s^2: the potential's strength
  double sigma = 0.3;             ///< m: the potential's range
  double step_time = 2.0;         ///< Delta t, s: how far ahead the other's step is foreseen (ellipse)
  double fov_half_angle = 100.0;  ///< phi, degrees either side of the walking direction
  double fov_outside_weight = 0.5;  ///< c: weight of what a person does not see

  // Wall force -grad U, U = U0 exp(-d / R), d from the body's centre to the nearest wall surface: Helbing &
  // Molnar eq. (5); U0 10 m^2/s^2, R 0.2 m in PySocialForce [space_repulsive_force].
  double u0 = 10.0;        ///< U0, m^2/s^2
  double wall_range = 0.2; ///< R, m

  // Speed cap: |v| <= 1.3 v0 (Helbing & Molnar eq. 9 with v_max = 1.3 v0, PySocialForce max_speed_multiplier).
  double max_speed_factor = 1.3;

  /// Others farther than this exert no force (all forces above are below 1e-3 m/s^2 there; rfbsim), m.
  double interaction_range = 8.0;
  /// rfbsim: without physics nothing stops a body at a wall, so the part of the velocity that would bring
  /// the centre nearer than this to a wall surface is removed, m (half a body radius plus a margin).
  double min_wall_gap = 0.2;

  // Walking behaviour (rfbsim choices).
  double goal_radius = 0.3;       ///< m: a goal counts as reached this near (PySocialForce: 0.2)
  double waypoint_radius = 0.6;   ///< m: an intermediate waypoint counts as reached this near
  /// m: a goal that someone else stands on (so near that the person could not stand there without touching
  /// them) counts as reached this near, so that people do not shove a standing robot, the avatar or
  /// another person off their spot
  double taken_goal_radius = 1.0;
  /// m: the gap a person keeps from every other body. Closing in on one, a person slows so as to stop this
  /// far from it (walking around or away stays free), so that people never shove the robot, the avatar or
  /// each other; the physics would let them.
  double min_body_gap = 0.05;
  /// m/s^2: the braking people plan with when closing in on a body; below what their legs can do in the
  /// physics (PhysicsParams::person_drive_force / person_mass, 4.3 m/s^2), so that they can always stop.
  double body_braking = 3.0;
  double clearance = 0.3;         ///< m: routes keep the body centre this far from walls (radius + 5 cm)
  double turn_rate = 4.0;         ///< rad/s: how fast the body turns toward the way it walks
  double stall_time = 4.0;        ///< s: no progress toward the waypoint for this long => re-plan
  /// The participant's avatar repels people like a person, and people keep min_body_gap from it, do not
  /// spawn on it and give up a goal it stands on.
  bool react_to_avatar = true;
  bool react_to_robot = true;     ///< the same for the robot
};

/// What the social force needs to know of another body.
struct Neighbour {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s
  double radius = 0.25;                                ///< m, body radius
};

/// Goal force (v0 e - v) / tau, m/s^2; `direction` is a unit vector (zero to stop where it stands).
[[nodiscard]] Eigen::Vector2d goal_force(const Eigen::Vector2d& velocity, const Eigen::Vector2d& direction,
                                         double desired_speed, const SocialForceParams& params);

/// The force `other` exerts on `self` (m/s^2) under params.model; `direction` is self's desired walking
/// direction (unit, or zero), used by the field of view.
[[nodiscard]] Eigen::Vector2d pedestrian_force(const Neighbour& self, const Eigen::Vector2d& direction,
                                               const Neighbour& other, const SocialForceParams& params);

/// The nearest wall's push on a body centred at `position` (m/s^2), from the distance field.
[[nodiscard]] Eigen::Vector2d wall_force(const Eigen::Vector2d& position, const DistanceField& field,
                                         const SocialForceParams& params);

/// `velocity` shortened to at most max_speed_factor * desired_speed.
[[nodiscard]] Eigen::Vector2d cap_speed(const Eigen::Vector2d& velocity, double desired_speed,
                                        const SocialForceParams& params);

}  // namespace rfbsim::sim
