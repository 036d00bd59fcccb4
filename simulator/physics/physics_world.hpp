// SPDX-License-Identifier: GPL-2.0-or-later
// PhysicsWorld: the rigid-body stage of the tick (ODE, kept private). It moves the avatar, the people and
// the robot toward the velocities their controllers want, with bounded drive forces, among the map's walls
// and the props; it writes back poses and actual velocities and reports contacts as world events.
#pragma once

#include <memory>

#include "world/world.hpp"

namespace rfbsim::sim {

/// Physical constants of the bodies and contacts; the defaults are tuned for a 60 Hz tick.
struct PhysicsParams {
  double avatar_height = 1.75;         ///< m
  double avatar_stride_length = 1.4;   ///< m per gait cycle, as AvatarParams::stride_length
  double person_mass = 70.0;           ///< kg, the avatar and each person
  double robot_mass = 6.4;             ///< kg (Kuri)
  /// N per map axis: the most horizontal force legs put on the floor to reach the wanted velocity. 300 N
  /// (about 4 m/s^2 for 70 kg, below the 0.6 g that shoe friction allows) is what lets a walking avatar
  /// keep pushing the robot.
  double person_drive_force = 300.0;
  /// N per map axis: the wheels' traction (about 0.65 * 6.4 kg * g). Far below a person's, so the robot
  /// cannot push a person, and a person who keeps pushing moves the robot.
  double robot_drive_force = 40.0;
  double static_friction = 0.05;       ///< Coulomb coefficient against walls and props: bodies slide along
  double body_friction = 0.3;          ///< Coulomb coefficient between two bodies
  /// N/m and N s/m: the contacts' spring and damper, damped beyond critical for 70 kg so nothing bounces.
  /// With the sub-steps below a walking body sinks about 1.5 cm into a wall on impact and about 7 mm
  /// (surface layer + push / stiffness) while it keeps pushing.
  double contact_stiffness = 2.0e5;
  double contact_damping = 1.0e4;
  /// m: how deep a body may sink before ODE pushes it out. A body leaning on a wall stays that deep, so
  /// its contact persists tick after tick instead of flickering, and a touch is one event.
  double contact_surface_layer = 0.005;
  /// m/s: the fastest ODE may push a sunk body out; ODE's push-out is real velocity, and more would bounce.
  double max_correcting_speed = 0.1;
  /// Agents that want to stand (wanted speed below 0.05 m/s) brace: legs hold with this force, N per map
  /// axis, more than a walker pushes with, so walking into a standing person moves neither (with equal
  /// forces the pair would keep drifting with the momentum of the impact).
  double person_hold_force = 450.0;
  double min_impulse = 0.5;            ///< N s: a touch whose impulse stays below this is not reported
  int substeps = 2;                    ///< ODE steps per tick: 1/120 s, so a body moves < 1.2 cm per step
};

/// The bodies of one World in ODE. Build it after the world's people and robot exist; afterwards the world
/// stays the owner of every pose (a pose changed elsewhere moves the body) and people added or removed
/// later get or lose their bodies. All calls on one thread. Many PhysicsWorlds may live in one process.
class PhysicsWorld {
 public:
  /// Static boxes for the map's walls and the props, a body per agent at its pose and current velocity.
  explicit PhysicsWorld(const World& world, PhysicsParams params = {});
  ~PhysicsWorld();
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  /// Advances the bodies by dt seconds toward the wanted velocities (avatar: speed along its yaw; people:
  /// velocity; robot: velocity and yaw_rate); writes back positions, actual velocities, the robot's yaw and
  /// the avatar's gait; replaces world.contacts with the contacts that began in this tick (tick = world.tick).
  /// Does not advance world.tick. Deterministic: the same inputs give bit-identical outputs.
  void step(World& world, double dt);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::sim
