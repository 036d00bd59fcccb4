// SPDX-License-Identifier: GPL-2.0-or-later
// Avatar kinematics and camera rig: one fixed step of walking, turning and camera adjustment.
#pragma once

#include "avatar/avatar_controls.hpp"
#include "map/grid_map.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// How the avatar moves; defaults are a comfortable walk for keyboard control.
struct AvatarParams {
  double walk_speed = 1.3;       ///< m/s forward (a typical human walking speed)
  double backward_speed = 0.7;   ///< m/s backward
  double turn_rate = 1.8;        ///< rad/s
  double acceleration = 6.0;     ///< m/s^2 toward the commanded speed (no instant jumps on the screen)
  double radius = 0.25;          ///< m, body radius for wall contact (as the world's Avatar)
  double stride_length = 1.4;    ///< m per full gait cycle (two steps)
};

/// How the camera rig moves; heights in metres above the floor.
struct CameraParams {
  double min_height = 0.8;
  double max_height = 6.0;
  double climb_rate = 1.5;  ///< m/s while Up or Down is held
};

/// Turns the avatar and changes its speed toward what `controls` command, by dt seconds; does not move it
/// (the physics does, or step_avatar).
void steer_avatar(const AvatarParams& params, const ControlState& controls, double dt, Avatar& avatar);

/// Advances the walking cycle and the distance walked by `moved` metres.
void advance_avatar_gait(const AvatarParams& params, double moved, Avatar& avatar);

/// Steers and moves the avatar by dt seconds without physics, sliding along the map's walls.
void step_avatar(const AvatarParams& params, const ControlState& controls, const GridMap& map, double dt,
                 Avatar& avatar);

/// Raises or lowers the camera by dt seconds under `controls`, within the limits.
void step_camera(const CameraParams& params, const ControlState& controls, double dt, CameraRig& camera);

}  // namespace rfbsim::sim
