// SPDX-License-Identifier: GPL-2.0-or-later
// Running the robot to a goal: in a shipped scenario through the whole Simulation, or in a hand-made world
// with only the robot stack and physics (people placed by hand, standing where the test puts them).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "app/simulation.hpp"
#include "physics/physics_world.hpp"
#include "robot/nav_metrics.hpp"
#include "robot/robot_stack.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::test {

/// How one run ended and what it measured.
struct NavRun {
  bool arrived = false;
  bool failed = false;
  double end_time = 0.0;       ///< s when it arrived or failed (or the limit)
  std::string last_detail;     ///< the last event's detail
  std::vector<sim::RobotEvent> events;
  sim::NavSummary metrics;
  double max_estimate_error = 0.0;  ///< m, worst distance between the estimate and the truth
  /// Whether the robot's body ever overlapped a wall or prop cell by more than the 4 cm that contact
  /// softness and the costmap's cell rounding allow.
  bool hit_wall = false;
};

/// Watches a world tick by tick: events, metrics, localization error, wall clearance. For debugging a run,
/// RFBSIM_NAV_TRACE=1 prints the robot once a simulated second and every robot-at-fault collision; =2 adds
/// the global path and the chosen trajectory.
class NavWatch {
 public:
  /// Takes one stepped tick; returns true once the robot arrived or failed.
  bool observe(const sim::World& world, double dt) {
    const int faults_before = trace_ ? metrics_.summary().robot_on_person : 0;
    metrics_.observe(world, dt);
    const sim::Robot& robot = *world.robot;
    if (trace_ && metrics_.summary().robot_on_person != faults_before) {
      std::fprintf(stderr, "COLLISION t %.2f robot %.2f %.2f yaw %.2f vel %.2f %.2f state %s\n", world.time, robot.pose.x,
                   robot.pose.y, robot.pose.yaw, robot.velocity.x(), robot.velocity.y(), sim::robot_state_name(robot.state));
      for (const auto& p : world.people) {
        const double d = std::hypot(p.pose.x - robot.pose.x, p.pose.y - robot.pose.y);
        if (d < 1.5) std::fprintf(stderr, "  person %d at %.2f %.2f vel %.2f %.2f dist %.2f\n", p.id, p.pose.x, p.pose.y, p.velocity.x(), p.velocity.y(), d);
      }
    }
    run_.max_estimate_error = std::max(run_.max_estimate_error, std::hypot(robot.estimate.x - robot.pose.x,
                                                                           robot.estimate.y - robot.pose.y));
    if (world.obstacles.disc_hits_wall(robot.pose.x, robot.pose.y, robot.radius - 0.04)) run_.hit_wall = true;
    for (const sim::RobotEvent& event : world.robot_events) {
      run_.events.push_back(event);
      run_.last_detail = event.detail;
      if (event.state == sim::RobotState::Arrived) run_.arrived = true;
      if (event.state == sim::RobotState::Failed) run_.failed = true;
    }
    run_.end_time = world.time;
    if (trace_ && world.tick % 60 == 0) {
      std::fprintf(stderr, "t %6.1f pose %6.2f %6.2f %5.2f est %6.2f %6.2f v %5.2f w %5.2f state %s path %zu traj %zu\n",
                   world.time, robot.pose.x, robot.pose.y, robot.pose.yaw, robot.estimate.x, robot.estimate.y,
                   robot.velocity.norm(), robot.yaw_rate, sim::robot_state_name(robot.state),
                   robot.nav.global_path.size(), robot.nav.local_trajectory.size());
      if (trace_paths_ && !robot.nav.global_path.empty()) {
        std::fprintf(stderr, "  path:");
        for (std::size_t i = 0; i < robot.nav.global_path.size(); i += 10) std::fprintf(stderr, " (%.2f,%.2f)", robot.nav.global_path[i].x(), robot.nav.global_path[i].y());
        std::fprintf(stderr, "\n  traj:");
        for (const auto& p : robot.nav.local_trajectory) std::fprintf(stderr, " (%.2f,%.2f)", p.x(), p.y());
        std::fprintf(stderr, "\n");
      }
      for (const auto& e : world.robot_events) std::fprintf(stderr, "  event %s %s\n", sim::robot_state_name(e.state), e.detail.c_str());
    }
    return run_.arrived || run_.failed;
  }
  [[nodiscard]] NavRun result() const {
    NavRun out = run_;
    out.metrics = metrics_.summary();
    return out;
  }

 private:
  const char* trace_switch_ = std::getenv("RFBSIM_NAV_TRACE");
  bool trace_ = trace_switch_ != nullptr;
  bool trace_paths_ = trace_ && trace_switch_[0] == '2';
  NavRun run_;
  sim::NavMetrics metrics_;
};

/// A shipped scenario with its robot's mission, as sim_rfb builds it.
inline std::unique_ptr<sim::Simulation> make_mission_simulation(const std::string& name, std::uint64_t seed,
                                                                sim::ScenarioOverrides overrides = {},
                                                                const sim::RobotParams* params = nullptr) {
  sim::Scenario scenario = sim::load_scenario(std::string(RFBSIM_SCENARIO_DIR) + "/" + name + ".yaml");
  overrides.seed = seed;
  sim::apply_overrides(scenario, overrides);
  sim::RobotSetup setup = sim::robot_setup(scenario);
  if (params) setup.params = *params;
  return std::make_unique<sim::Simulation>(sim::SimulationParams{}, sim::make_world(scenario), scenario.crowd,
                                           setup);
}

/// Steps `simulation` until its robot arrives or fails, or `limit` s of simulated time pass.
inline NavRun run_to_goal(sim::Simulation& simulation, double limit) {
  NavWatch watch;
  const double dt = simulation.params().dt;
  while (simulation.world().time < limit) {
    simulation.step();
    if (watch.observe(simulation.world(), dt)) break;
  }
  return watch.result();
}

/// A hand-made world with the robot stack and physics but no crowd system: people stand where put.
class BareWorld {
 public:
  BareWorld(sim::World world, sim::RobotSetup setup) : world_(std::move(world)) {
    stack_ = std::make_unique<sim::RobotStack>(world_, std::move(setup));
    physics_ = std::make_unique<sim::PhysicsWorld>(world_);
  }
  void step() {
    stack_->step(world_, dt_);
    physics_->step(world_, dt_);
    ++world_.tick;
    world_.time = static_cast<double>(world_.tick) * dt_;
  }
  NavRun run_to_goal(double limit) {
    NavWatch watch;
    while (world_.time < limit) {
      step();
      if (watch.observe(world_, dt_)) break;
    }
    return watch.result();
  }
  [[nodiscard]] const sim::World& world() const { return world_; }
  sim::RobotStack& stack() { return *stack_; }
  sim::World& world_mut() { return world_; }

 private:
  double dt_ = 1.0 / 60.0;
  sim::World world_;
  std::unique_ptr<sim::RobotStack> stack_;
  std::unique_ptr<sim::PhysicsWorld> physics_;
};

/// An open rectangle width x height m at `resolution`, walled all round one cell thick.
inline sim::GridMap walled_room(double width, double height, double resolution = 0.05) {
  return sim::walled_grid(width, height, resolution);
}

/// Blocks the axis-aligned box [x0, x1] x [y0, y1] (m) of `map`.
inline void add_wall(sim::GridMap& map, double x0, double y0, double x1, double y1) {
  map.block_box(0.5 * (x0 + x1), 0.5 * (y0 + y1), x1 - x0, y1 - y0, 0.0);
}

/// A person standing still at (x, y).
inline sim::Person standing_person(double x, double y, int id = 1) {
  sim::Person person;
  person.id = id;
  person.pose = {x, y, 0.0};
  person.desired_speed = 0.0;
  return person;
}

/// A world on `map` (walls only, no props) with the robot at `start` and the avatar parked at `avatar`.
inline sim::World bare_world(const sim::GridMap& map, const sim::Pose2& start, const sim::Pose2& avatar) {
  sim::World world;
  world.map = map;
  world.obstacles = map;
  sim::Robot robot;
  robot.pose = start;
  robot.estimate = start;
  world.robot = robot;
  world.avatar.pose = avatar;
  return world;
}

/// A robot setup that goes to one goal.
inline sim::RobotSetup goto_setup(const sim::Pose2& goal, std::uint64_t seed = 1) {
  sim::RobotSetup setup;
  setup.mission.kind = sim::MissionSpec::Kind::GoTo;
  setup.mission.waypoints = {goal};
  setup.mission.waypoint_names = {""};
  setup.seed = seed;
  return setup;
}

}  // namespace rfbsim::test
