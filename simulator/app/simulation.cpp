// SPDX-License-Identifier: GPL-2.0-or-later
// Simulation: the fixed-step stages in order.
#include "app/simulation.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

namespace rfbsim::sim {

namespace {

World with_people(World world, const Crowd& crowd) {
  world.people = crowd.spawn();
  return world;
}

}  // namespace

Simulation::Simulation(SimulationParams params, World initial, CrowdSpec crowd, RobotSetup robot)
    : params_(params),
      crowd_(initial, std::move(crowd), params.crowd),
      physics_() {
  world_ = with_people(std::move(initial), crowd_);
  if (world_.robot) robot_ = std::make_unique<RobotStack>(world_, std::move(robot));
  physics_ = std::make_unique<PhysicsWorld>(world_, params_.physics);
}

Simulation::~Simulation() = default;

void Simulation::step() {
  // Input (already applied to controls_): the avatar's wanted speed and heading.
  steer_avatar(params_.avatar, controls_.state(), params_.dt, world_.avatar);
  step_camera(params_.camera, controls_.state(), params_.dt, world_.camera);
  // Crowd: each person's wanted velocity from the social forces.
  crowd_.step(world_, params_.dt);
  // Robot: sense, localize, plan, and set the wheels' wanted velocity.
  if (robot_) robot_->step(world_, params_.dt);
  // Physics: everybody moves as far as walls, props and each other let them; contacts become events.
  auto& before = positions_before_physics_;
  before.clear();
  for (const Person& person : world_.people) before.emplace_back(person.pose.x, person.pose.y);
  physics_->step(world_, params_.dt);
  for (std::size_t i = 0; i < world_.people.size(); ++i) {
    Person& person = world_.people[i];
    advance_gait(person, (Eigen::Vector2d(person.pose.x, person.pose.y) - before[i]).norm());
  }
  ++world_.tick;
  world_.time = static_cast<double>(world_.tick) * params_.dt;
}

bool Simulation::command_robot(double v, double w) {
  return robot_ != nullptr && robot_->external_command(world_, v, w);
}

std::optional<std::string> Simulation::send_robot_goal(const Pose2& goal) {
  if (!robot_) return std::string("there is no robot");
  return robot_->send_goal(world_, goal);
}

std::string status_json(const World& world, int clients, std::uint64_t frames_rendered,
                        const std::string& streams_json) {
  char text[768];
  std::snprintf(text, sizeof text,
                "{\"tick\":%llu,\"time\":%.4f,\"clients\":%d,\"frames_rendered\":%llu,"
                "\"avatar\":{\"x\":%.4f,\"y\":%.4f,\"yaw\":%.4f,\"speed\":%.4f},\"camera_height\":%.3f,"
                "\"people\":%zu",
                static_cast<unsigned long long>(world.tick), world.time, clients,
                static_cast<unsigned long long>(frames_rendered), world.avatar.pose.x, world.avatar.pose.y,
                world.avatar.pose.yaw, world.avatar.speed, world.camera.height, world.people.size());
  std::string json = text;
  if (world.robot) {
    const Robot& r = *world.robot;
    std::snprintf(text, sizeof text,
                  ",\"robot\":{\"x\":%.4f,\"y\":%.4f,\"yaw\":%.4f,\"speed\":%.4f,\"state\":\"%s\","
                  "\"estimate\":{\"x\":%.4f,\"y\":%.4f,\"yaw\":%.4f}}",
                  r.pose.x, r.pose.y, r.pose.yaw, r.velocity.norm(), robot_state_name(r.state), r.estimate.x,
                  r.estimate.y, r.estimate.yaw);
    json += text;
  }
  // Last, so that readers looking for the first "x", "speed" or "clients" find the world's and the count.
  return json + ",\"streams\":" + streams_json + "}";
}

}  // namespace rfbsim::sim
