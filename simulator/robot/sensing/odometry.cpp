// SPDX-License-Identifier: GPL-2.0-or-later
// WheelOdometry: the true motion split into rot1, trans, rot2, corrupted, and integrated.
#include "robot/sensing/odometry.hpp"

#include <cmath>

#include "robot/sensing/motion_delta.hpp"

namespace rfbsim::sim {

WheelOdometry::WheelOdometry(OdometryParams params, Pose2 start, std::uint64_t seed)
    : params_(params), last_true_(start), pose_(start), rng_(seed) {
  pose_.yaw = normalize_angle(pose_.yaw);
}

bool WheelOdometry::update(const Pose2& true_pose) {
  if (!is_finite_pose(true_pose)) return false;
  // The exact split (no minimum drive): with a perfect model the odometry must follow the truth exactly.
  MotionDelta delta = decompose_motion(last_true_, true_pose, 0.0);
  last_true_ = true_pose;
  if (!is_finite_pose(pose_)) return false;  // a bad start pose stays bad; nothing to integrate into

  const double driven = std::abs(delta.trans);
  const double turned = std::abs(normalize_angle(delta.rot1 + delta.rot2));
  // Random parts: variances proportional to the motion (a random walk), so the rate of updates does not
  // matter. Two draws every update, so the stream stays aligned whatever the motion.
  const double rot_sd = std::sqrt(params_.rot_stddev_per_rad * params_.rot_stddev_per_rad * turned +
                                  params_.rot_stddev_per_m * params_.rot_stddev_per_m * driven);
  const double trans_sd = std::sqrt(params_.trans_stddev_per_m * params_.trans_stddev_per_m * driven +
                                    params_.trans_stddev_per_rad * params_.trans_stddev_per_rad * turned);
  const double rot_noise = rot_sd * unit_gaussian_(rng_);
  const double trans_noise = trans_sd * unit_gaussian_(rng_);

  // Systematic parts: scale errors on what the wheels measured, and the drift of unequal wheels (signed
  // with the drive, since reversing winds it back). Half the heading error goes before the drive and half
  // after, as on an arc.
  const double heading_error = params_.yaw_drift_per_m * delta.trans + rot_noise;
  delta.rot1 = delta.rot1 * (1.0 + params_.rot_scale_error) + 0.5 * heading_error;
  delta.rot2 = delta.rot2 * (1.0 + params_.rot_scale_error) + 0.5 * heading_error;
  delta.trans = delta.trans * (1.0 + params_.trans_scale_error) + trans_noise;
  pose_ = compose_motion(pose_, delta);
  distance_ += std::abs(delta.trans);
  return true;
}

}  // namespace rfbsim::sim
