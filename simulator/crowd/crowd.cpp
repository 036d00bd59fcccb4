// SPDX-License-Identifier: GPL-2.0-or-later
// Crowd: spawning, goals and waypoints, and the per-tick social force integration.
#include "crowd/crowd.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <utility>

namespace rfbsim::sim {

namespace {

// SplitMix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit hash to seed each person's stream.
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Our own conversions from the raw stream: the standard distributions' algorithms differ between
// standard libraries, and a scenario must give the same crowd everywhere.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double uniform(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }

std::size_t uniform_index(std::mt19937_64& rng, std::size_t n) {
  return static_cast<std::size_t>(rng() % static_cast<std::uint64_t>(n));
}

double normal(std::mt19937_64& rng) {  // Box-Muller, one value per call
  const double u1 = 1.0 - uniform01(rng);  // (0, 1]: log stays finite
  const double u2 = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

double wrap_angle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

// Shirt colours, muted and distinct from the robot and the landmarks.
constexpr std::uint32_t kShirts[] = {0x8a5a9e, 0x3f6fb5, 0xb5473f, 0x4f8f4a, 0xc9a227, 0x2f8f8f,
                                     0x7a7a7a, 0xd07a3a, 0x5b4a8a, 0x9e3f6a, 0x2d4f6f, 0xe0e0e0};

constexpr double kSpawnGap = 0.15;  // m kept between bodies and from walls at spawn

// Whether someone other than `self` stands so near `point` that `self` could not stand there without
// touching them (keeping `gap`).
bool taken_by_other(const Eigen::Vector2d& point, const std::vector<Neighbour>& bodies, std::size_t self,
                    double gap) {
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    const double apart = bodies[self].radius + bodies[j].radius + gap;
    if (j != self && (bodies[j].position - point).squaredNorm() < apart * apart) return true;
  }
  return false;
}

// `v` (self's velocity) with its speed toward each nearby body limited to what still lets self stop
// `gap` short of it, braking at `braking`: people walk around, away from or up to whoever is near, never
// into them. The limit is on self's own speed, not the speed relative to the other: a pushed robot moves
// away as fast as it is pushed, and a relative limit would let the push go on.
Eigen::Vector2d keep_off_bodies(Eigen::Vector2d v, const std::vector<Neighbour>& bodies, std::size_t self,
                                double gap, double braking) {
  constexpr double kLookAhead = 1.0;  // m of gap within which the limit applies
  const Neighbour& me = bodies[self];
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    if (j == self) continue;
    const Eigen::Vector2d d = bodies[j].position - me.position;
    const double distance = d.norm();
    const double free = distance - me.radius - bodies[j].radius - gap;
    if (distance < 1e-9 || free >= kLookAhead) continue;
    const Eigen::Vector2d toward = d / distance;
    const double closing = v.dot(toward);
    const double allowed = std::sqrt(2.0 * braking * std::max(0.0, free));
    if (closing > allowed) v -= (closing - allowed) * toward;
  }
  return v;
}

}  // namespace

Crowd::Crowd(const World& world, CrowdSpec spec, SocialForceParams params)
    : spec_(std::move(spec)), params_(params), planner_(world.obstacles) {
  const std::size_t count = static_cast<std::size_t>(std::max(0, spec_.count));
  walkers_.resize(count);
  spawned_.reserve(count);
  std::vector<Neighbour> standing;
  append_avatar_and_robot(world, standing);
  for (std::size_t i = 0; i < count; ++i) place(i, standing, spawned_);
}

void Crowd::append_avatar_and_robot(const World& world, std::vector<Neighbour>& bodies) const {
  if (params_.react_to_avatar) {
    const Avatar& a = world.avatar;
    const Eigen::Vector2d heading(std::cos(a.pose.yaw), std::sin(a.pose.yaw));
    bodies.push_back({{a.pose.x, a.pose.y}, a.speed * heading, a.radius});
  }
  if (params_.react_to_robot && world.robot) {
    const Robot& r = *world.robot;
    bodies.push_back({{r.pose.x, r.pose.y}, r.velocity, r.radius});
  }
}

std::vector<Person> Crowd::spawn() const { return spawned_; }

std::vector<Eigen::Vector2d> Crowd::waypoints(std::size_t index) const {
  const Walker& w = walkers_.at(index);
  return {w.waypoints.begin() + static_cast<std::ptrdiff_t>(std::min(w.next, w.waypoints.size())),
          w.waypoints.end()};
}

Eigen::Vector2d Crowd::random_free_point(std::mt19937_64& rng) const {
  // Free cells keeping the clearance, drawn uniformly; a map with none gives its centre.
  const GridMap& m = planner_.map();
  for (int attempt = 0; attempt < 1000 && m.width > 0 && m.height > 0; ++attempt) {
    const Cell c{static_cast<int>(uniform_index(rng, static_cast<std::size_t>(m.width))),
                 static_cast<int>(uniform_index(rng, static_cast<std::size_t>(m.height)))};
    if (planner_.walkable(c, params_.clearance)) return m.cell_centre(c);
  }
  return m.cell_centre({m.width / 2, m.height / 2});
}

void Crowd::place(std::size_t index, const std::vector<Neighbour>& standing, std::vector<Person>& placed) {
  Walker& w = walkers_[index];
  w.rng.seed(splitmix64(spec_.seed ^ splitmix64(static_cast<std::uint64_t>(index))));
  Person p;
  p.id = static_cast<int>(index) + 1;
  // Body first, so that the same draws come first whatever the routes are.
  p.desired_speed = std::clamp(spec_.speed_mean + spec_.speed_std * normal(w.rng), spec_.speed_min, spec_.speed_max);
  p.height = uniform(w.rng, 1.55, 1.95);
  p.rgb = kShirts[uniform_index(w.rng, std::size(kShirts))];

  // Candidate starts: on a route segment (with a direction), or near a drawn goal, or anywhere free. After
  // a few failures the candidate is moved sideways by up to 1 m, so a crowded route still finds room.
  const GridMap& m = planner_.map();
  const auto clear = [&](const Eigen::Vector2d& q) {
    if (m.disc_hits_wall(q.x(), q.y(), p.radius + kSpawnGap)) return false;
    const bool clear_of_standing = std::all_of(standing.begin(), standing.end(), [&](const Neighbour& o) {
      return (o.position - q).norm() >= p.radius + o.radius + kSpawnGap;
    });
    return clear_of_standing && std::all_of(placed.begin(), placed.end(), [&](const Person& o) {
      return std::hypot(o.pose.x - q.x(), o.pose.y - q.y()) >= p.radius + o.radius + kSpawnGap;
    });
  };
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  bool found = false;
  for (int attempt = 0; attempt < 200 && !found; ++attempt) {
    Eigen::Vector2d q;
    if (!spec_.routes.empty()) {
      w.route = static_cast<int>(index % spec_.routes.size());
      const auto& route = spec_.routes[static_cast<std::size_t>(w.route)];
      if (route.size() <= 1) {
        q = route.empty() ? Eigen::Vector2d::Zero() : route[0];
        w.target = 0;
        w.direction = 1;
      } else {
        const std::size_t segment = uniform_index(w.rng, route.size() - 1);
        const double along = uniform01(w.rng);
        q = route[segment] + along * (route[segment + 1] - route[segment]);
        w.direction = uniform01(w.rng) < 0.5 ? 1 : -1;
        w.target = static_cast<int>(w.direction > 0 ? segment + 1 : segment);
      }
    } else if (!spec_.goals.empty()) {
      w.target = static_cast<int>(uniform_index(w.rng, spec_.goals.size()));
      q = spec_.goals[static_cast<std::size_t>(w.target)];
    } else {
      q = random_free_point(w.rng);
    }
    if (attempt >= 20 || (spec_.routes.empty() && !spec_.goals.empty())) {
      const double angle = uniform(w.rng, 0.0, 2.0 * std::numbers::pi);
      const double reach = uniform(w.rng, 0.0, 1.0);
      q += reach * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    start = q;
    found = clear(q);
  }
  // No room after all attempts: the last candidate, moved out of any wall; physics will part the bodies.
  if (!found) start = planner_.nearest_free(start);

  p.pose.x = start.x();
  p.pose.y = start.y();
  if (w.route >= 0) {
    const auto& route = spec_.routes[static_cast<std::size_t>(w.route)];
    w.goal = route.empty() ? start : route[static_cast<std::size_t>(w.target)];
  } else {
    choose_next_goal(w);  // away from the goal it starts at
  }
  plan_to_goal(w, start);
  const Eigen::Vector2d ahead = w.waypoints.empty() ? w.goal : w.waypoints.front();
  if ((ahead - start).norm() > 1e-9) p.pose.yaw = std::atan2(ahead.y() - start.y(), ahead.x() - start.x());
  placed.push_back(p);
}

void Crowd::choose_next_goal(Walker& w) {
  if (w.route >= 0) {
    // Back and forth along the route, turning at either end.
    const int n = static_cast<int>(spec_.routes[static_cast<std::size_t>(w.route)].size());
    if (n <= 1) return;
    if (w.target + w.direction < 0 || w.target + w.direction >= n) w.direction = -w.direction;
    w.target += w.direction;
    w.goal = spec_.routes[static_cast<std::size_t>(w.route)][static_cast<std::size_t>(w.target)];
  } else if (!spec_.goals.empty()) {
    // Another goal than the one just reached, when there is another.
    const std::size_t n = spec_.goals.size();
    std::size_t next = uniform_index(w.rng, n > 1 ? n - 1 : 1);
    if (n > 1 && next >= static_cast<std::size_t>(w.target)) ++next;
    w.target = static_cast<int>(next);
    w.goal = spec_.goals[next];
  } else {
    w.goal = random_free_point(w.rng);
  }
}

void Crowd::plan_to_goal(Walker& w, const Eigen::Vector2d& from) {
  PlannedRoute route = planner_.plan(from, w.goal, params_.clearance);
  // No path at all (a closed-off goal): walk straight at it; the walls' force keeps the body out of them.
  w.waypoints = route.waypoints.empty() ? std::vector<Eigen::Vector2d>{w.goal} : std::move(route.waypoints);
  w.next = 0;
  w.best_distance = (w.waypoints.front() - from).norm();
  w.stalled_for = 0.0;
}

Eigen::Vector2d Crowd::desired_direction(Walker& w, const Person& person, const std::vector<Neighbour>& bodies,
                                         std::size_t self, double dt) {
  const Eigen::Vector2d here(person.pose.x, person.pose.y);
  const bool single_point = w.route >= 0 && spec_.routes[static_cast<std::size_t>(w.route)].size() <= 1;
  // Waypoints reached (intermediate ones with a wider radius, so people round corners), then the goal.
  while (w.next + 1 < w.waypoints.size() && (w.waypoints[w.next] - here).norm() < params_.waypoint_radius) {
    ++w.next;
    w.best_distance = (w.waypoints[w.next] - here).norm();
    w.stalled_for = 0.0;
  }
  double distance = (w.waypoints[w.next] - here).norm();
  const bool last = w.next + 1 == w.waypoints.size();
  if (last && (distance < params_.goal_radius ||
               (distance < params_.taken_goal_radius &&
                taken_by_other(w.waypoints[w.next], bodies, self, params_.min_body_gap)))) {
    if (single_point) return Eigen::Vector2d::Zero();  // stands at (or next to) its only point
    ++w.goals_reached;
    choose_next_goal(w);
    plan_to_goal(w, here);
    distance = (w.waypoints[w.next] - here).norm();
  }
  // Stall: no progress for a while. Near its goal, a crowd is in the way: count it reached. Otherwise the
  // person was pushed off its route: plan again from here (once per stall, not every tick).
  if (distance < w.best_distance - 0.1) {
    w.best_distance = distance;
    w.stalled_for = 0.0;
  } else if ((w.stalled_for += dt) > params_.stall_time) {
    const double to_goal = (w.goal - here).norm();
    if (to_goal < 1.5 && !single_point) {
      ++w.goals_reached;
      choose_next_goal(w);
    }
    plan_to_goal(w, here);
    const Eigen::Vector2d v = w.waypoints[w.next] - here;
    return v.norm() > 1e-9 ? Eigen::Vector2d(v.normalized()) : Eigen::Vector2d::Zero();
  }
  if (distance < 1e-9) return Eigen::Vector2d::Zero();
  return (w.waypoints[w.next] - here) / distance;
}

void Crowd::step(World& world, double dt) {
  assert(world.people.size() == walkers_.size() && "Crowd::step: world.people is not what spawn() returned");
  const std::size_t n = std::min(world.people.size(), walkers_.size());
  // Everyone's forces from the same snapshot, so that the order of people does not matter: the people,
  // then the avatar and the robot as people moving with their velocities.
  std::vector<Neighbour>& now = bodies_;
  now.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Person& p = world.people[i];
    now[i] = {{p.pose.x, p.pose.y}, p.velocity, p.radius};
  }
  append_avatar_and_robot(world, now);
  const DistanceField& field = planner_.field();
  for (std::size_t i = 0; i < n; ++i) {
    Person& person = world.people[i];
    const Eigen::Vector2d e = desired_direction(walkers_[i], person, now, i, dt);
    Eigen::Vector2d force = goal_force(now[i].velocity, e, person.desired_speed, params_);
    for (std::size_t j = 0; j < now.size(); ++j) {
      if (j != i) force += pedestrian_force(now[i], e, now[j], params_);
    }
    force += wall_force(now[i].position, field, params_);

    // Semi-implicit Euler: the new velocity is what moves the body this tick.
    Eigen::Vector2d v = cap_speed(now[i].velocity + dt * force, person.desired_speed, params_);
    v = keep_off_bodies(v, now, i, params_.min_body_gap, params_.body_braking);
    // Without physics nothing stops a body at a wall: drop the part of v that would bring it too near.
    const Eigen::Vector2d next = now[i].position + dt * v;
    if (field.at(next.x(), next.y()) < params_.min_wall_gap) {
      const Eigen::Vector2d away = field.gradient(now[i].position.x(), now[i].position.y());
      const double toward = v.dot(away);
      if (toward < 0.0) v -= toward * away;
    }
    if (!v.allFinite()) v.setZero();
    person.velocity = v;

    // Turn toward the motion at a bounded rate, so that the body does not snap around.
    const double speed = v.norm();
    if (speed > 0.05) {
      const double turn = wrap_angle(std::atan2(v.y(), v.x()) - person.pose.yaw);
      const double max_turn = params_.turn_rate * dt;
      person.pose.yaw = wrap_angle(person.pose.yaw + std::clamp(turn, -max_turn, max_turn));
    }
  }
}

void advance_gait(Person& person, double moved_distance) {
  const double stride = 0.8 * person.height;
  const double phase = person.gait_phase + 2.0 * std::numbers::pi * moved_distance / stride;
  person.gait_phase = std::fmod(phase, 2.0 * std::numbers::pi);
  if (person.gait_phase < 0.0) person.gait_phase += 2.0 * std::numbers::pi;
}

void move_people_freely(World& world, double dt) {
  for (Person& p : world.people) {
    p.pose.x += p.velocity.x() * dt;
    p.pose.y += p.velocity.y() * dt;
    advance_gait(p, p.velocity.norm() * dt);
  }
}

}  // namespace rfbsim::sim
