// SPDX-License-Identifier: GPL-2.0-or-later
// Avatar kinematics: unicycle model with bounded acceleration and wall sliding.
#include "avatar/avatar_motion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rfbsim::sim {

void steer_avatar(const AvatarParams& params, const ControlState& controls, double dt, Avatar& avatar) {
  // Commanded speeds: opposite keys cancel.
  double target_speed = 0.0;
  if (controls.forward && !controls.backward) target_speed = params.walk_speed;
  if (controls.backward && !controls.forward) target_speed = -params.backward_speed;
  double yaw_rate = 0.0;
  if (controls.turn_left) yaw_rate += params.turn_rate;
  if (controls.turn_right) yaw_rate -= params.turn_rate;

  // Approach the commanded speed at bounded acceleration.
  const double max_change = params.acceleration * dt;
  avatar.speed += std::clamp(target_speed - avatar.speed, -max_change, max_change);
  avatar.yaw_rate = yaw_rate;
  avatar.pose.yaw = std::remainder(avatar.pose.yaw + yaw_rate * dt, 2.0 * std::numbers::pi);
}

void advance_avatar_gait(const AvatarParams& params, double moved, Avatar& avatar) {
  // The gait advances with distance, so the legs never slide over the floor.
  avatar.distance_walked += moved;
  const double direction = avatar.speed < 0.0 ? -1.0 : 1.0;
  avatar.gait_phase = std::fmod(avatar.gait_phase + direction * moved / params.stride_length * 2.0 * std::numbers::pi,
                                2.0 * std::numbers::pi);
}

void step_avatar(const AvatarParams& params, const ControlState& controls, const GridMap& map, double dt,
                 Avatar& avatar) {
  steer_avatar(params, controls, dt, avatar);
  // Move each axis separately so that a wall blocks only the component into it (sliding).
  const double dx = avatar.speed * std::cos(avatar.pose.yaw) * dt;
  const double dy = avatar.speed * std::sin(avatar.pose.yaw) * dt;
  const double x0 = avatar.pose.x;
  const double y0 = avatar.pose.y;
  if (!map.disc_hits_wall(avatar.pose.x + dx, avatar.pose.y, params.radius)) avatar.pose.x += dx;
  if (!map.disc_hits_wall(avatar.pose.x, avatar.pose.y + dy, params.radius)) avatar.pose.y += dy;
  const double moved = std::hypot(avatar.pose.x - x0, avatar.pose.y - y0);
  const bool wants_to_move = controls.forward != controls.backward;
  if (moved == 0.0 && !wants_to_move) avatar.speed = 0.0;
  advance_avatar_gait(params, moved, avatar);
}

void step_camera(const CameraParams& params, const ControlState& controls, double dt, CameraRig& camera) {
  double climb = 0.0;
  if (controls.camera_up) climb += params.climb_rate;
  if (controls.camera_down) climb -= params.climb_rate;
  camera.height = std::clamp(camera.height + climb * dt, params.min_height, params.max_height);
}

}  // namespace rfbsim::sim
