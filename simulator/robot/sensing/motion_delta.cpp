// SPDX-License-Identifier: GPL-2.0-or-later
// MotionDelta: splitting a pose change into rot1, trans, rot2 and applying one.
#include "robot/sensing/motion_delta.hpp"

#include <cmath>
#include <numbers>

namespace rfbsim::sim {

double normalize_angle(double angle) {
  if (!std::isfinite(angle)) return angle;
  // remainder() lands in [-pi, pi]; move -pi to +pi so the range is half-open.
  double wrapped = std::remainder(angle, 2.0 * std::numbers::pi);
  if (wrapped <= -std::numbers::pi) wrapped += 2.0 * std::numbers::pi;
  return wrapped;
}

MotionDelta decompose_motion(const Pose2& from, const Pose2& to, double min_trans) {
  const double dx = to.x - from.x;
  const double dy = to.y - from.y;
  const double turn = normalize_angle(to.yaw - from.yaw);
  MotionDelta delta;
  delta.trans = std::hypot(dx, dy);
  if (delta.trans < min_trans || delta.trans == 0.0) {
    // Turning in place: the projection on the heading keeps a tiny drive's sign and most of its length.
    delta.trans = std::cos(from.yaw) * dx + std::sin(from.yaw) * dy;
    delta.rot2 = turn;
    return delta;
  }
  delta.rot1 = normalize_angle(std::atan2(dy, dx) - from.yaw);
  // Moving backwards: face the way the robot faces and drive a negative distance instead.
  if (std::abs(delta.rot1) > std::numbers::pi / 2) {
    delta.rot1 = normalize_angle(delta.rot1 - std::numbers::pi);
    delta.trans = -delta.trans;
  }
  delta.rot2 = normalize_angle(turn - delta.rot1);
  return delta;
}

Pose2 compose_motion(const Pose2& pose, const MotionDelta& delta) {
  const double heading = pose.yaw + delta.rot1;
  return {pose.x + delta.trans * std::cos(heading), pose.y + delta.trans * std::sin(heading),
          normalize_angle(heading + delta.rot2)};
}

bool is_finite_pose(const Pose2& pose) {
  return std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.yaw);
}

}  // namespace rfbsim::sim
