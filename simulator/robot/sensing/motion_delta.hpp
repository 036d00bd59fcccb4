// SPDX-License-Identifier: GPL-2.0-or-later
// MotionDelta: a planar motion split as the odometry motion model does (turn rot1, drive trans, turn rot2;
// Thrun, Burgard, Fox, Probabilistic Robotics, section 5.4), shared by wheel odometry and AMCL.
#pragma once

#include "world/world.hpp"

namespace rfbsim::sim {

/// A motion in the frame of the pose it starts from: turn by rot1, drive trans along the new heading, then
/// turn by rot2. trans is signed: driving backwards is a negative trans with |rot1| <= pi/2, not a half turn
/// there and back, so that noise scaled by the turns stays small for a robot reversing.
struct MotionDelta {
  double rot1 = 0.0;   ///< rad
  double trans = 0.0;  ///< m, negative when driving backwards
  double rot2 = 0.0;   ///< rad
};

/// `angle` wrapped into (-pi, pi], rad. Non-finite input comes back unchanged.
[[nodiscard]] double normalize_angle(double angle);

/// The motion that takes `from` to `to`. When the straight distance is below `min_trans` (m) the direction
/// of travel is meaningless (a robot turning in place), so rot1 is 0 and the drive goes along from's heading
/// (AMCL uses 0.01 m); with min_trans 0 the split is exact: compose(from, decompose(from, to, 0)) == to
/// up to rounding.
[[nodiscard]] MotionDelta decompose_motion(const Pose2& from, const Pose2& to, double min_trans);

/// `pose` moved by `delta`; the yaw comes back wrapped into (-pi, pi].
[[nodiscard]] Pose2 compose_motion(const Pose2& pose, const MotionDelta& delta);

/// Whether x, y and yaw are all finite.
[[nodiscard]] bool is_finite_pose(const Pose2& pose);

}  // namespace rfbsim::sim
