// SPDX-License-Identifier: GPL-2.0-or-later
// Crowd: the pedestrians' minds. It spawns the people of a CrowdSpec, gives each a route planned on the
// obstacle map, and every tick sets the velocity each person wants (social force model) and turns them
// toward it. It never moves a pose: physics does, or move_people_freely where there is no physics.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "crowd/crowd_spec.hpp"
#include "crowd/route_planner.hpp"
#include "crowd/social_force.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// The crowd system. Constant after construction: the spec, the parameters, the planner (with the distance
/// field of World::obstacles, built once). Per-person walking state (route, goal, waypoints, random
/// stream) lives here too, index for index with World::people as spawn() returned them.
class Crowd {
 public:
  /// Builds the distance field and planner from world.obstacles and decides where everyone starts.
  Crowd(const World& world, CrowdSpec spec, SocialForceParams params = {});

  /// spec.count people with ids 1.., placed on their routes or near their goals, clear of walls and of
  /// the people before them; speeds, heights and shirt colours from each person's own random stream
  /// (seeded from spec.seed and the index, so adding a person does not change the others).
  [[nodiscard]] std::vector<Person> spawn() const;

  /// One tick for every person in index order: advance waypoints, sum the social forces, integrate the
  /// velocity (semi-implicit Euler, speed cap) into person.velocity, and turn person.pose.yaw toward the
  /// motion. Leaves positions alone. world.people must be what spawn() returned, since moved.
  void step(World& world, double dt);

  /// Where person `index` is heading now (its current goal, not the next waypoint), m.
  [[nodiscard]] Eigen::Vector2d goal(std::size_t index) const { return walkers_.at(index).goal; }
  /// Person `index`'s remaining waypoints, the next first (for debug drawing), m.
  [[nodiscard]] std::vector<Eigen::Vector2d> waypoints(std::size_t index) const;
  /// How many goals (route points or drawn goals) person `index` has reached so far.
  [[nodiscard]] int goals_reached(std::size_t index) const { return walkers_.at(index).goals_reached; }
  [[nodiscard]] const SocialForceParams& params() const { return params_; }
  [[nodiscard]] const RoutePlanner& planner() const { return planner_; }

 private:
  // One person's walking state.
  struct Walker {
    std::mt19937_64 rng;      // the person's stream: spawn draws, then its goal draws
    int route = -1;           // index into spec.routes; -1 when walking between drawn goals
    int target = 0;           // index of the route point or drawn goal it walks to
    int direction = 1;        // +1 or -1 along the route
    Eigen::Vector2d goal = Eigen::Vector2d::Zero();
    std::vector<Eigen::Vector2d> waypoints;
    std::size_t next = 0;     // index of the waypoint it walks to
    double best_distance = 0.0;  // nearest it has come to the waypoint, for stall detection, m
    double stalled_for = 0.0;    // s without progress toward the waypoint
    int goals_reached = 0;
  };

  /// Places person `index` clear of walls, of `standing` (the avatar and the robot) and of `placed`.
  void place(std::size_t index, const std::vector<Neighbour>& standing, std::vector<Person>& placed);
  /// Appends the avatar and the robot to `bodies`, as bodies people react to (as react_to_avatar and
  /// react_to_robot say).
  void append_avatar_and_robot(const World& world, std::vector<Neighbour>& bodies) const;
  void choose_next_goal(Walker& walker);
  void plan_to_goal(Walker& walker, const Eigen::Vector2d& from);
  [[nodiscard]] Eigen::Vector2d random_free_point(std::mt19937_64& rng) const;
  /// The way person `self` wants to walk; `bodies` are everyone this tick (people first, in order, then
  /// the avatar and the robot), to tell whether its goal is taken.
  [[nodiscard]] Eigen::Vector2d desired_direction(Walker& walker, const Person& person,
                                                  const std::vector<Neighbour>& bodies, std::size_t self, double dt);

  CrowdSpec spec_;
  SocialForceParams params_;
  RoutePlanner planner_;
  std::vector<Person> spawned_;
  std::vector<Walker> walkers_;
  std::vector<Neighbour> bodies_;  // reused each step: everyone's position and velocity this tick
};

/// Moves every person by velocity * dt, with no physics (tests, benches), advancing the gait.
void move_people_freely(World& world, double dt);

/// Advances a person's gait_phase by `moved_distance` (m): one full cycle (two steps) per stride of
/// 0.8 * height, a typical adult's stride (about 0.41 * height per step), wrapped to [0, 2 pi).
void advance_gait(Person& person, double moved_distance);

}  // namespace rfbsim::sim
