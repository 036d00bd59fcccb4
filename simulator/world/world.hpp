// SPDX-License-Identifier: GPL-2.0-or-later
// World: the plain state of one simulation (what is where now). Systems read and write it; the renderer
// and the status reporter only read it. No GL, EGL or network types here.
#pragma once

#include <cstdint>
#include <vector>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

/// A pose on the floor plane: metres and radians, yaw counter-clockwise from +x.
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
};

/// An axis-aligned box standing on the floor (crates, obstacles).
struct Prop {
  double x = 0.0;       ///< centre, m
  double y = 0.0;       ///< centre, m
  double size_x = 0.5;  ///< full extent along x, m
  double size_y = 0.5;  ///< full extent along y, m
  double height = 0.5;  ///< m
  std::uint32_t rgb = 0xb08850;  ///< colour 0xRRGGBB
};

/// The participant's avatar.
struct Avatar {
  Pose2 pose;
  double speed = 0.0;         ///< signed forward speed, m/s (negative walking backwards)
  double yaw_rate = 0.0;      ///< rad/s
  double gait_phase = 0.0;    ///< radians of the walking cycle, advances with distance walked
  double distance_walked = 0.0;  ///< m, total
};

/// The third-person camera's adjustable part; where it is follows from the avatar each frame.
struct CameraRig {
  double height = 2.2;    ///< eye height above the floor, m (Up/Down change it)
  double distance = 3.2;  ///< horizontal distance behind the avatar, m
};

/// Everything that changes while the simulation runs, plus the static map it runs in.
struct World {
  GridMap map;
  std::vector<Prop> props;
  Avatar avatar;
  CameraRig camera;
  std::uint64_t tick = 0;  ///< fixed steps taken
  double time = 0.0;       ///< simulated seconds = tick * dt
};

}  // namespace rfbsim::sim
