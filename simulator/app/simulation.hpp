// SPDX-License-Identifier: GPL-2.0-or-later
// Simulation: the model (parameters, fixed step) and the state (World) of one session, stepped by ticks.
// No GL and no network: the app feeds it key events and reads the world to draw and report it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "avatar/avatar_controls.hpp"
#include "avatar/avatar_motion.hpp"
#include "crowd/crowd.hpp"
#include "physics/physics_world.hpp"
#include "robot/robot_stack.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What does not change during a session.
struct SimulationParams {
  double dt = 1.0 / 60.0;  ///< s per tick
  AvatarParams avatar;
  CameraParams camera;
  SocialForceParams crowd;
  PhysicsParams physics;
};

class Simulation {
 public:
  /// Spawns the crowd described by `crowd` into `initial`, builds the robot's stack from `robot` when the
  /// world has a robot (no mission when not given), and builds the physics of the result. Throws
  /// std::invalid_argument for robot parameters that cannot work.
  Simulation(SimulationParams params, World initial, CrowdSpec crowd = {}, RobotSetup robot = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Applies one key event; it takes effect from the next step.
  void apply_key(std::uint32_t keysym, bool down) { controls_.apply_key(keysym, down); }
  /// Releases every control (the participant left).
  void release_controls() { controls_.release_all(); }
  /// Advances one fixed tick: input, avatar, crowd, robot (sense, localize, plan, act), physics, clock.
  void step();

  [[nodiscard]] const World& world() const { return world_; }
  [[nodiscard]] const SimulationParams& params() const { return params_; }
  [[nodiscard]] const ControlState& controls() const { return controls_.state(); }
  /// The robot's navigation stack; null when the world has no robot.
  [[nodiscard]] const RobotStack* robot_stack() const { return robot_.get(); }
  /// Sends the robot to `goal` (see RobotStack::send_goal); the reason when refused or there is no robot.
  std::optional<std::string> send_robot_goal(const Pose2& goal);
  /// An external controller's velocity command (docs/ros.md), applied from the next step; false when there is
  /// no robot or it is not under external control (the command is then ignored).
  bool command_robot(double v, double w);

 private:
  SimulationParams params_;
  World world_;
  AvatarControls controls_;
  Crowd crowd_;
  std::unique_ptr<RobotStack> robot_;
  std::unique_ptr<PhysicsWorld> physics_;
  std::vector<Eigen::Vector2d> positions_before_physics_;  // reused each tick: how far each person moved
};

/// The status document served at /status.json: tick, time, avatar pose, camera height, people, robot,
/// contacts so far, plus what the caller adds about clients and frames, and last "streams": `streams_json`, a
/// JSON array written as given (sim_rfb's viewers' streams, app/stream_status.hpp).
std::string status_json(const World& world, int clients, std::uint64_t frames_rendered,
                        const std::string& streams_json = "[]");

}  // namespace rfbsim::sim
