// SPDX-License-Identifier: GPL-2.0-or-later
// RobotStack: the robot's stages in order, on their own schedules.
#include "robot/robot_stack.hpp"

#include <algorithm>
#include <chrono>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace rfbsim::sim {

namespace {

/// Adds the wall-clock time of one run of a stage to `times` when it goes out of scope.
class StageTimer {
 public:
  StageTimer(StageTimes& times, NavStage stage) : times_(times), stage_(static_cast<std::size_t>(stage)) {}
  ~StageTimer() {
    times_.seconds[stage_] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    ++times_.runs[stage_];
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  StageTimes& times_;
  std::size_t stage_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

const Robot& robot_of(const World& world) {
  if (!world.robot) throw std::invalid_argument("RobotStack: the world has no robot");
  return *world.robot;
}

double positive_rate(double hz, const char* name) {
  if (!(hz > 0.0) || !std::isfinite(hz)) {
    throw std::invalid_argument(std::string("robot: ") + name + " must be a positive number of Hz");
  }
  return 1.0 / hz;
}

/// Moves a world point seen from the true pose into the frame the robot believes it is in.
Eigen::Vector2d believed(const Eigen::Vector2d& point, const Pose2& truth, const Pose2& estimate) {
  const Eigen::Rotation2Dd turn(estimate.yaw - truth.yaw);
  return turn * (point - Eigen::Vector2d(truth.x, truth.y)) + Eigen::Vector2d(estimate.x, estimate.y);
}

/// The setup with the parameters that must agree made to agree: DWA's window is one control period wide,
/// and the costmaps' footprint is the robot's body plus the padding.
RobotSetup synced(RobotSetup setup, double robot_radius) {
  RobotParams& p = setup.params;
  p.dwa.controller_frequency = p.navigator.controller_frequency;
  p.dwa.robot_radius = robot_radius;
  p.global_costmap.robot_radius = robot_radius + p.footprint_padding;
  p.local_costmap.robot_radius = robot_radius + p.footprint_padding;
  return setup;
}

}  // namespace

const char* robot_control_name(RobotControl control) {
  return control == RobotControl::kExternal ? "external" : "builtin";
}

std::optional<RobotControl> robot_control_from_name(std::string_view name) {
  if (name == "builtin") return RobotControl::kBuiltin;
  if (name == "external") return RobotControl::kExternal;
  return std::nullopt;
}

void people_in_view(const World& world, const Pose2& pose, double range, std::vector<SeenPerson>& out) {
  out.clear();
  const auto consider = [&](const Eigen::Vector2d& at, const Eigen::Vector2d& velocity, double radius) {
    const Eigen::Vector2d offset = at - Eigen::Vector2d(pose.x, pose.y);
    const double distance = offset.norm();
    if (distance > range || !std::isfinite(distance)) return;
    // In view when the ray toward the centre reaches the body before any wall or prop.
    const double angle = std::atan2(offset.y(), offset.x());
    const double clear = world.obstacles.ray_cast(pose.x, pose.y, angle, distance);
    if (clear + 1e-9 < distance - radius) return;
    out.push_back({at, velocity, radius});
  };
  for (const Person& p : world.people) consider({p.pose.x, p.pose.y}, p.velocity, p.radius);
  const Avatar& a = world.avatar;
  consider({a.pose.x, a.pose.y}, a.speed * Eigen::Vector2d(std::cos(a.pose.yaw), std::sin(a.pose.yaw)), a.radius);
}

RobotStack::RobotStack(const World& world, RobotSetup setup)
    : setup_(synced(std::move(setup), robot_of(world).radius)),
      drive_(setup_.params.drive),
      odometry_(setup_.params.odometry, robot_of(world).pose, setup_.seed ^ 0x6f646f6dULL),
      global_(world.obstacles, setup_.params.global_costmap),
      local_(world.obstacles, setup_.params.local_costmap),
      navigator_(setup_.params.navigator, setup_.params.planner, setup_.params.dwa),
      mission_(setup_.mission, setup_.seed ^ 0x6d697373ULL),
      lidar_rng_(setup_.seed ^ 0x6c696461ULL) {
  check_lidar_params(setup_.params.lidar);
  if (!(setup_.command_timeout > 0.0) || !std::isfinite(setup_.command_timeout)) {
    throw std::invalid_argument("command_timeout must be a positive number of seconds");
  }
  positive_rate(setup_.params.navigator.controller_frequency, "controller_frequency");
  positive_rate(setup_.params.global_update_frequency, "global_update_frequency");
  if (setup_.params.localization == Localization::Amcl) {
    amcl_.emplace(world.obstacles, setup_.params.amcl, robot_of(world).pose, setup_.seed ^ 0x616d636cULL);
  }
}

RobotStack::~RobotStack() = default;

void RobotStack::step(World& world, double dt) {
  world.robot_events.clear();
  Robot& robot = *world.robot;
  const double now = world.time;
  if (!mission_started_) {
    mission_started_ = true;
    next_mission_goal(world);
  }
  if (setup_.control == RobotControl::kExternal) {
    watch_external_commands(world);
    external_goal_reached(world);
  }

  // Sense: the wheels count every tick; the lidar sweeps at its own rate, from the true pose.
  odometry_.update(robot.pose);
  if (now + 1e-9 >= next_scan_time_) {
    StageTimer timer(times_, NavStage::Lidar);
    collect_lidar_bodies(world, bodies_);
    cast_scan_into(scan_, world.obstacles, bodies_, robot.pose, now, setup_.params.lidar, lidar_rng_);
    scan_fresh_ = true;
    ++scans_;
    next_scan_time_ = std::max(next_scan_time_ + 1.0 / setup_.params.lidar.rate_hz, now);
  }
  // Localize, map, plan at the controller's rate; the mission moves on after a pause at a waypoint.
  if (now + 1e-9 >= next_cycle_time_) {
    if (setup_.control == RobotControl::kExternal) {
      external_cycle(world);
    } else {
      control_cycle(world);
    }
    next_cycle_time_ = std::max(next_cycle_time_ + 1.0 / setup_.params.navigator.controller_frequency, now);
  }
  if (resume_mission_at_ >= 0.0 && now + 1e-9 >= resume_mission_at_) {
    resume_mission_at_ = -1.0;
    next_mission_goal(world);
  }
  // Act: the wheels ramp toward the command every tick; the head follows the way ahead.
  drive_.step(dt, robot);
  turn_head(robot, dt);
  record_events(world);
}

// Where the robot believes it is: AMCL on the odometry and the fresh scan, or the true pose without AMCL.
// Written to Robot::estimate and returned.
Pose2 RobotStack::localize(Robot& robot) {
  Pose2 estimate = robot.pose;
  if (amcl_) {
    StageTimer timer(times_, NavStage::Localization);
    amcl_->update(odometry_.pose(), scan_fresh_ ? &scan_ : nullptr);
    estimate = amcl_->estimate();
  }
  robot.estimate = estimate;
  return estimate;
}

void RobotStack::control_cycle(World& world) {
  Robot& robot = *world.robot;
  const double now = world.time;
  ++cycles_;
  const Pose2 estimate = localize(robot);

  {
    // The people detector sees from the true pose; what it reports lands where the robot believes it is.
    StageTimer timer(times_, NavStage::Costmaps);
    people_in_view(world, robot.pose, setup_.params.lidar.range_max, seen_);
    if (amcl_) {
      const Eigen::Rotation2Dd turn(estimate.yaw - robot.pose.yaw);
      for (SeenPerson& person : seen_) {
        person.position = believed(person.position, robot.pose, estimate);
        person.velocity = turn * person.velocity;
      }
    }
    const LaserScan* scan = scan_fresh_ ? &scan_ : nullptr;
    local_.update(estimate, scan, seen_);
    if (now + 1e-9 >= next_global_update_) {
      // Only a scan taken this cycle: an older one marked from today's pose would leave ghosts.
      global_.update(estimate, scan, seen_);
      next_global_update_ = std::max(next_global_update_ + 1.0 / setup_.params.global_update_frequency, now);
    }
    scan_fresh_ = false;
  }

  // Someone standing at the goal makes them the goal: the robot stops at social distance from them.
  std::optional<Eigen::Vector2d> goal_person;
  if (const auto& goal = navigator_.goal()) goal_person = goal_person_at(*goal, seen_, setup_.params.navigator);
  navigator_.set_people(seen_);
  const NavigatorTimes before = navigator_.times();
  const NavCommand command =
      navigator_.cycle(now, estimate, drive_.v(), drive_.w(), global_.grid(), local_.grid(), goal_person);
  const NavigatorTimes& after = navigator_.times();
  const auto plan_index = static_cast<std::size_t>(NavStage::GlobalPlan);
  const auto local_index = static_cast<std::size_t>(NavStage::LocalPlan);
  times_.seconds[plan_index] += after.plan_seconds - before.plan_seconds;
  times_.runs[plan_index] += after.plans - before.plans;
  times_.seconds[local_index] += after.control_seconds - before.control_seconds;
  times_.runs[local_index] += after.controls - before.controls;
  if (command.clear_obstacles_beyond) {
    const Eigen::Vector2d at(estimate.x, estimate.y);
    global_.clear_obstacles_beyond(at, *command.clear_obstacles_beyond);
    local_.clear_obstacles_beyond(at, *command.clear_obstacles_beyond);
  }
  command_drive(command.v, command.w, now);

  // A patrol or a wander goes on to its next waypoint after a pause, whether this one was reached or not.
  const RobotState state = navigator_.state();
  const bool done = state == RobotState::Arrived || state == RobotState::Failed;
  const auto kind = mission_.spec().kind;
  if (done && !goal_finished_) {
    goal_finished_ = true;
    if (kind == MissionSpec::Kind::Patrol || kind == MissionSpec::Kind::Wander) {
      // At least a second after a failure, so that a run of refused goals cannot flood the events.
      const double pause = setup_.params.navigator.waypoint_pause;
      resume_mission_at_ = now + (state == RobotState::Failed ? std::max(pause, 1.0) : pause);
    }
  }

  // What the robot believes and plans, for status and the debug overlay.
  robot.state = state;
  robot.nav.global_path = navigator_.global_path();
  robot.nav.local_trajectory = navigator_.local_trajectory();
  robot.nav.social = local_.social();
  robot.nav.goal = navigator_.goal();
  head_target_ = 0.0;
  if (!robot.nav.global_path.empty()) {
    const Eigen::Vector2d ahead =
        point_ahead(robot.nav.global_path, {estimate.x, estimate.y}, setup_.params.head_lookahead)
            .value_or(robot.nav.global_path.back());
    const double bearing = std::atan2(ahead.y() - estimate.y, ahead.x() - estimate.x);
    const double limit = setup_.params.head_max_angle;
    head_target_ = std::clamp(std::remainder(bearing - estimate.yaw, 2.0 * std::numbers::pi), -limit, limit);
  }
}

void RobotStack::next_mission_goal(World& world) {
  if (const auto goal = mission_.next_goal()) {
    mission_goal_ = *goal;
    if (setup_.control == RobotControl::kExternal) {
      // The controller outside is told the goal (ROS's /goal_pose); reaching it is its business.
      world.robot->nav.goal = *goal;
      goal_finished_ = false;
      return;
    }
    goal_finished_ = false;
    navigator_.set_goal(*goal, world.obstacles, world.robot->radius);
    world.robot->state = navigator_.state();
  }
}

std::optional<std::string> RobotStack::send_goal(World& world, const Pose2& goal) {
  resume_mission_at_ = -1.0;
  goal_finished_ = false;
  mission_started_ = true;  // a goal sent before the first tick is not replaced by the mission's first
  mission_goal_ = goal;
  if (setup_.control == RobotControl::kExternal) {
    world.robot->nav.goal = goal;
    return std::nullopt;
  }
  auto refusal = navigator_.set_goal(goal, world.obstacles, world.robot->radius);
  world.robot->state = navigator_.state();
  return refusal;
}

void RobotStack::command_drive(double v, double w, double now) {
  drive_.command(v, w);
  if (command_.sequence > 0 && command_.v == v && command_.w == w) return;  // the same command again: not news
  command_ = {v, w, now, command_.sequence + 1};
}

bool RobotStack::external_command(const World& world, double v, double w) {
  if (setup_.control != RobotControl::kExternal) return false;
  external_v_ = std::isfinite(v) ? v : 0.0;
  external_w_ = std::isfinite(w) ? w : 0.0;
  external_time_ = world.time;
  return true;
}

// Every tick under external control: the latest command goes to the wheels at once (not at the next control
// cycle), so that a command takes effect within a tick of arriving; a command older than the timeout stops the
// robot once, with an event saying so, and the next fresh command drives it again.
void RobotStack::watch_external_commands(World& world) {
  const bool fresh = external_time_ >= 0.0 && world.time - external_time_ <= setup_.command_timeout + 1e-9;
  if (fresh) {
    if (external_stale_) {
      external_stale_ = false;
      world.robot->state = RobotState::Moving;
      world.robot_events.push_back({world.tick, RobotState::Moving, "external control: commands arriving"});
    }
    command_drive(external_v_, external_w_, external_time_);
    return;
  }
  if (!external_stale_) {
    external_stale_ = true;
    world.robot->state = RobotState::Idle;
    char detail[96];
    std::snprintf(detail, sizeof detail, "external control: no command for %.2f s, stopped", setup_.command_timeout);
    world.robot_events.push_back({world.tick, RobotState::Idle, detail});
    command_drive(0.0, 0.0, world.time);
  }
}

// Under external control the mission still moves on: once the robot's centre is within the navigator's goal
// tolerance of the goal, a patrol or a wander gives the next waypoint after its pause, so /goal_pose follows.
void RobotStack::external_goal_reached(World& world) {
  if (!mission_goal_ || goal_finished_ || resume_mission_at_ >= 0.0) return;
  const Pose2& at = world.robot->pose;
  if (std::hypot(at.x - mission_goal_->x, at.y - mission_goal_->y) > setup_.params.navigator.xy_goal_tolerance) return;
  goal_finished_ = true;
  const auto kind = mission_.spec().kind;
  if (kind == MissionSpec::Kind::Patrol || kind == MissionSpec::Kind::Wander) {
    resume_mission_at_ = world.time + setup_.params.navigator.waypoint_pause;
  }
}

// The control cycle under external control: localization still runs (the robot's belief is published as
// map->odom), the costmaps and planners do not (nobody reads them, and they are most of the stack's cost).
void RobotStack::external_cycle(World& world) {
  Robot& robot = *world.robot;
  ++cycles_;
  localize(robot);
  scan_fresh_ = false;
  robot.nav.global_path.clear();
  robot.nav.local_trajectory.clear();
  head_target_ = 0.0;
}

void RobotStack::record_events(World& world) {
  for (NavEvent& event : navigator_.take_events()) {
    world.robot_events.push_back({world.tick, event.state, std::move(event.detail)});
  }
}

void RobotStack::turn_head(Robot& robot, double dt) const {
  const double step = setup_.params.head_max_rate * dt;
  robot.head_yaw += std::clamp(head_target_ - robot.head_yaw, -step, step);
}

}  // namespace rfbsim::sim
