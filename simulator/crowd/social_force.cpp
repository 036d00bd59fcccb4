// SPDX-License-Identifier: GPL-2.0-or-later
// The social force model's terms: goal, pedestrian (Moussaid 2009 or Helbing & Molnar 1995), wall, speed cap.
#include "crowd/social_force.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rfbsim::sim {

namespace {

// Moussaid et al. 2009, eq. (3)-(4): the interaction vector D = lambda (v_i - v_j) + e_ij (e_ij: unit, from
// i to j) sets the direction t the interaction acts along and the range B = gamma |D|; theta is the angle
// from t to e_ij. A braking term pushes back along -t, an angular term turns i aside, away from j.
Eigen::Vector2d moussaid_force(const Neighbour& self, const Neighbour& other, const SocialForceParams& params) {
  const Eigen::Vector2d diff = other.position - self.position;
  const double distance = diff.norm();
  if (distance < 1e-9) return Eigen::Vector2d::Zero();  // no direction to push in; walls and goals part them
  const Eigen::Vector2d e = diff / distance;
  const Eigen::Vector2d d_vec = params.lambda_importance * (self.velocity - other.velocity) + e;
  const double d_norm = d_vec.norm();
  if (d_norm < 1e-9) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d t = d_vec / d_norm;
  const Eigen::Vector2d left(-t.y(), t.x());
  const double theta = std::atan2(t.x() * e.y() - t.y() * e.x(), t.dot(e));
  const double b = params.gamma * d_norm;
  // sign(0) counts as +1: two people exactly head-on both step to their right instead of deadlocking (the
  // paper's sign function is 0 there; PySocialForce keeps that and such pairs stop nose to nose).
  const double side = theta < 0.0 ? -1.0 : 1.0;
  const double braking = std::exp(-distance / b - std::pow(params.n_prime * b * theta, 2));
  const double turning = std::exp(-distance / b - std::pow(params.n * b * theta, 2));
  return -params.social_factor * (braking * t + side * turning * left);
}

// Helbing & Molnar 1995, eq. (4): V = V0 exp(-b / sigma), with 2b = sqrt((|r| + |r - s|)^2 - s^2), r = r_a - r_b
// and s = v_b Delta t the other's next step. The force -dV/dr is taken analytically; eq. (7) weighs what lies
// outside the field of view by c.
Eigen::Vector2d helbing_molnar_force(const Neighbour& self, const Eigen::Vector2d& direction,
                                     const Neighbour& other, const SocialForceParams& params) {
  const Eigen::Vector2d r = self.position - other.position;
  const Eigen::Vector2d step = other.velocity * params.step_time;
  const Eigen::Vector2d r_ahead = r - step;
  const double r_norm = r.norm();
  const double ahead_norm = r_ahead.norm();
  if (r_norm < 1e-9 || ahead_norm < 1e-9) return Eigen::Vector2d::Zero();
  const double sum = r_norm + ahead_norm;
  const double b = 0.5 * std::sqrt(std::max(sum * sum - step.squaredNorm(), 1e-12));
  // db/dr = (|r| + |r - s|) / (4 b) * (r / |r| + (r - s) / |r - s|).
  const Eigen::Vector2d db_dr = sum / (4.0 * b) * (r / r_norm + r_ahead / ahead_norm);
  const Eigen::Vector2d force = params.v0 / params.sigma * std::exp(-b / params.sigma) * db_dr;
  // In view when the other (the direction of -force) lies within phi of the walking direction.
  const double cos_phi = std::cos(params.fov_half_angle * std::numbers::pi / 180.0);
  const bool seen = direction.dot(-force) >= force.norm() * cos_phi;
  return seen ? force : params.fov_outside_weight * force;
}

}  // namespace

Eigen::Vector2d goal_force(const Eigen::Vector2d& velocity, const Eigen::Vector2d& direction, double desired_speed,
                           const SocialForceParams& params) {
  return (desired_speed * direction - velocity) / params.relaxation_time;
}

Eigen::Vector2d pedestrian_force(const Neighbour& self, const Eigen::Vector2d& direction, const Neighbour& other,
                                 const SocialForceParams& params) {
  if ((other.position - self.position).squaredNorm() > params.interaction_range * params.interaction_range) {
    return Eigen::Vector2d::Zero();
  }
  switch (params.model) {
    case PedestrianModel::Moussaid2009:
      return moussaid_force(self, other, params);
    case PedestrianModel::HelbingMolnar1995:
      return helbing_molnar_force(self, direction, other, params);
  }
  return Eigen::Vector2d::Zero();
}

Eigen::Vector2d wall_force(const Eigen::Vector2d& position, const DistanceField& field,
                           const SocialForceParams& params) {
  // -grad U0 exp(-d / R) = U0 / R exp(-d / R) grad d: away from the nearest wall surface.
  const double d = field.at(position.x(), position.y());
  if (d > params.interaction_range) return Eigen::Vector2d::Zero();
  return params.u0 / params.wall_range * std::exp(-d / params.wall_range) *
         field.gradient(position.x(), position.y());
}

Eigen::Vector2d cap_speed(const Eigen::Vector2d& velocity, double desired_speed, const SocialForceParams& params) {
  const double limit = params.max_speed_factor * desired_speed;
  const double speed = velocity.norm();
  return speed > limit && speed > 0.0 ? Eigen::Vector2d(velocity * (limit / speed)) : velocity;
}

}  // namespace rfbsim::sim
