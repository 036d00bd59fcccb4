// SPDX-License-Identifier: GPL-2.0-or-later
// DiffDrive: the robot's wheels. It takes a wanted (v, w) from the navigator and turns it, tick by tick, into
// what the wheels can do within their velocity and acceleration limits; physics then moves the body (so
// pushes, walls and people are real) and the robot's heading turns at the wheels' yaw rate.
#pragma once

#include "world/world.hpp"

namespace rfbsim::sim {

/// Physical limits of a Kuri-like base (docs/sources.md, SEAN's Kuri). The navigator's own limits (DWA's
/// max_vel_x, SEAN-EP ran 0.3 m/s) are tighter; these bound whatever anything asks of the wheels.
struct DriveLimits {
  double max_vel_x = 0.5;        ///< m/s forward (Kuri)
  double min_vel_x = -0.2;       ///< m/s: most it backs up
  double max_vel_theta = 3.0;    ///< rad/s either way (Kuri)
  double acc_lim_x = 1.0;        ///< m/s^2, speeding up and braking
  double acc_lim_theta = 4.0;    ///< rad/s^2
  double wheel_radius = 0.035;   ///< m (Kuri), for wheel speeds
  double wheel_separation = 0.175;  ///< m (Kuri)
};

/// Wheel angular speeds (rad/s) for a body motion.
struct WheelSpeeds {
  double left = 0.0;
  double right = 0.0;
};

/// Left and right wheel speeds of a differential drive moving at v (m/s) and w (rad/s).
WheelSpeeds wheel_speeds(const DriveLimits& limits, double v, double w);

class DiffDrive {
 public:
  explicit DiffDrive(DriveLimits limits = {}) : limits_(limits) {}

  /// What the navigator wants from now on (clamped to the limits; NaN reads as stop).
  void command(double v, double w);
  /// Moves the actual (v, w) toward the command by at most acc * dt, and writes the robot's wanted world
  /// velocity (v along its heading) and yaw rate for physics to carry out.
  void step(double dt, Robot& robot);
  /// Stops at once (a new session, or the participant left): no ramp.
  void halt(Robot& robot);

  [[nodiscard]] double v() const { return v_; }  ///< m/s, the wheels' forward speed now
  [[nodiscard]] double w() const { return w_; }  ///< rad/s, the wheels' turn rate now
  [[nodiscard]] const DriveLimits& limits() const { return limits_; }

 private:
  DriveLimits limits_;
  double wanted_v_ = 0.0, wanted_w_ = 0.0;
  double v_ = 0.0, w_ = 0.0;
};

}  // namespace rfbsim::sim
