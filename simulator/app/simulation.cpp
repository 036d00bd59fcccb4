// SPDX-License-Identifier: GPL-2.0-or-later
// Simulation: the fixed-step stages in order.
#include "app/simulation.hpp"

#include <cstdio>

namespace rfbsim::sim {

Simulation::Simulation(SimulationParams params, World initial)
    : params_(params), world_(std::move(initial)), physics_(std::make_unique<PhysicsWorld>(world_, params_.physics)) {}

Simulation::~Simulation() = default;

void Simulation::step() {
  // Input (already applied to controls_): the avatar's wanted speed and heading, and the camera rig.
  steer_avatar(params_.avatar, controls_.state(), params_.dt, world_.avatar);
  step_camera(params_.camera, controls_.state(), params_.dt, world_.camera);
  // Physics: everybody moves as far as walls, props and each other let them (the avatar's gait with
  // the distance it really moved); contacts that began become events in world_.contacts.
  physics_->step(world_, params_.dt);
  ++world_.tick;
  world_.time = static_cast<double>(world_.tick) * params_.dt;
}

std::string status_json(const World& world, int clients, std::uint64_t frames_rendered) {
  char text[512];
  std::snprintf(text, sizeof text,
                "{\"tick\":%llu,\"time\":%.4f,\"clients\":%d,\"frames_rendered\":%llu,"
                "\"avatar\":{\"x\":%.4f,\"y\":%.4f,\"yaw\":%.4f,\"speed\":%.4f},\"camera_height\":%.3f}",
                static_cast<unsigned long long>(world.tick), world.time, clients,
                static_cast<unsigned long long>(frames_rendered), world.avatar.pose.x, world.avatar.pose.y,
                world.avatar.pose.yaw, world.avatar.speed, world.camera.height);
  return text;
}

}  // namespace rfbsim::sim
