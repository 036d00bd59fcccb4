// SPDX-License-Identifier: GPL-2.0-or-later
// WheelOdometry: what the robot's wheel encoders say about where it is. Each update takes the true motion
// since the last one (rot1, trans, rot2 in the robot's frame), corrupts it by a drift model and adds it to
// the odometry pose, which therefore wanders off the truth as real dead reckoning does.
//
// The drift model (rfbsim's; the random part in the spirit of AMCL's odom_alpha1..4):
//   - Random noise whose variance grows in proportion to the motion (a random walk), so that the error over
//     a path does not depend on how often update() is called: stddevs are given for one metre driven or one
//     radian turned and grow with the square root of the distance or angle. (AMCL's alphas scale the
//     stddev with the motion itself, which is only right for a filter that updates every 0.2 m; at 60 Hz
//     it would make odometry almost perfect.) The turn that drives the noise is the net heading change,
//     not |rot1| + |rot2|, so a robot jittering on the spot (rot1 = -rot2) gathers no turning noise.
//   - Systematic errors as in UMBmark (Borenstein and Feng 1996): a translation scale error (wheel radius
//     off), a rotation scale error (wheel separation off) and a yaw drift per metre (unequal wheels).
// All zero is perfect odometry: the odometry pose then follows the true path exactly (up to rounding).
#pragma once

#include <cstdint>
#include <random>

#include "world/world.hpp"

namespace rfbsim::sim {

/// The odometry drift model. Defaults: a few centimetres and about a degree per ten metres, as a well
/// calibrated small base on a hard floor; sizes for Kuri's wheels (0.035 m radius, 0.175 m apart).
struct OdometryParams {
  /// m: stddev of the distance error after driving 1 m (grows with sqrt of the distance)  [like alpha3]
  double trans_stddev_per_m = 0.01;
  /// m: stddev of the distance error after turning 1 rad in place  [like alpha4]
  double trans_stddev_per_rad = 0.002;
  /// rad: stddev of the heading error after turning 1 rad (grows with sqrt of the angle)  [like alpha1]
  double rot_stddev_per_rad = 0.01;
  /// rad: stddev of the heading error after driving 1 m  [like alpha2]
  double rot_stddev_per_m = 0.005;
  /// Odometry reads (1 + this) times the distance driven: 0.002 is a wheel radius 0.2 % too large.
  double trans_scale_error = 0.002;
  /// Odometry reads (1 + this) times the angle turned: a wheel separation slightly too small.
  double rot_scale_error = 0.002;
  /// rad/m: heading the odometry believes it turned per metre driven straight (counter-clockwise positive);
  /// 0.002 is a right wheel about 0.035 % larger than the left.
  double yaw_drift_per_m = 0.002;
};

/// Dead reckoning from the true pose with drift. Deterministic per seed.
class WheelOdometry {
 public:
  /// `start` is the robot's true pose now and where the odometry pose begins (the odometry frame is the
  /// world frame until drift sets in).
  WheelOdometry(OdometryParams params, Pose2 start, std::uint64_t seed);

  /// Adds the motion from the previous true pose to `true_pose`, corrupted by the model. Call it as often
  /// as you like (every tick is fine). A non-finite true pose is ignored (returns false, nothing changes).
  bool update(const Pose2& true_pose);

  /// The odometry pose: m, m, rad (yaw in (-pi, pi]).
  [[nodiscard]] const Pose2& pose() const { return pose_; }
  /// Total distance the odometry believes it drove (absolute, m), for checks and the debug view.
  [[nodiscard]] double distance() const { return distance_; }
  [[nodiscard]] const OdometryParams& params() const { return params_; }

 private:
  OdometryParams params_;
  Pose2 last_true_;  // the true pose at the previous update
  Pose2 pose_;
  double distance_ = 0.0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_gaussian_{0.0, 1.0};
};

}  // namespace rfbsim::sim
