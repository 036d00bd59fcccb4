// SPDX-License-Identifier: GPL-2.0-or-later
// The ROS topics a session publishes (the same set in session.mcap and over rosbridge), and RosWorldSampler,
// which reads the world after each tick and yields the messages due then. Topic names are relative: the
// caller puts its namespace in front ("/clock" -> "/session_7/clock").
//
// Frames (REP 105): map (the world), odom (where wheel odometry began, drifting against map), base_link (the
// robot as it believes itself to be: map->odom composed with odom->base_link is the robot's estimate),
// robot_truth (where it really is), avatar and person_<id> (the participant and each pedestrian). All on the
// floor, z = 0. Times are simulated: tick k is k * 1e9 / tick_hz ns after the session began, exactly.
//
// The sampler only reads the world and the robot's stack; it owns no thread and no socket.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "robot/robot_stack.hpp"
#include "ros/msgs/ros_types.hpp"
#include "world/world.hpp"

namespace rfbsim::ros {

/// One topic: its name (relative, "/clock"), its type ("rosgraph_msgs/msg/Clock") and whether late
/// subscribers get its last message (transient-local durability, ROS 1's "latched").
struct TopicSpec {
  std::string name;
  std::string type;
  bool latched = false;
};

/// Every topic, in the order of docs/ros.md's table: /clock, /tf, /odom, /scan, /map, /scene_markers,
/// /cmd_vel, /people, /plan, /goal_pose, /events. The entries live as long as the program.
const std::vector<TopicSpec>& ros_topics();

/// The topic named `name` in ros_topics(), or null.
const TopicSpec* find_ros_topic(std::string_view name);

/// One message due: its topic (an entry of ros_topics()), when (simulated ns since the session began; the
/// MCAP log time) and what.
struct RosMessage {
  const TopicSpec* topic = nullptr;
  std::uint64_t time_ns = 0;
  RosPayload payload;
};

/// How often the sampler publishes.
struct RosSamplerOptions {
  int tick_hz = 60;  ///< the simulation's ticks per simulated second
  /// Hz of /tf, /odom and /people; must divide tick_hz (30 at 60 Hz: every other tick, which includes every
  /// tick trajectories.csv samples at 10 Hz).
  int pose_hz = 30;
};

/// Simulated nanoseconds at tick `tick` of a `tick_hz` simulation, exact (integer arithmetic, no drift).
std::uint64_t tick_time_ns(std::uint64_t tick, int tick_hz);

/// Reads the world tick by tick and yields the ROS messages due (see the table in docs/ros.md).
class RosWorldSampler {
 public:
  /// Throws std::invalid_argument when a rate is not positive or pose_hz does not divide tick_hz.
  explicit RosWorldSampler(RosSamplerOptions options);

  /// Appends to `out`, in table order, the messages due at the tick `world` is at now (world.tick). Call it
  /// once before the first step (tick 0: /map, /scene_markers and the first poses) and after every step.
  /// `robot` may be null: then there is no /odom, /scan, /cmd_vel, /plan or /goal_pose, and /tf carries no
  /// robot frames.
  void sample(const sim::World& world, const sim::RobotStack* robot, std::vector<RosMessage>& out);

  /// Appends one study event (an events.jsonl line without its newline) at simulated `time_ns` as /events.
  void add_event(std::uint64_t time_ns, std::string json_line, std::vector<RosMessage>& out);

 private:
  RosSamplerOptions options_;
  std::uint64_t pose_every_ = 1;  // ticks between pose messages
  bool scene_sent_ = false;       // /map and /scene_markers went out (once: they are latched)
  std::uint64_t scans_seen_ = 0;  // RobotStack::scans() when /scan last went out
  std::uint64_t command_seen_ = 0;  // DriveCommand::sequence when /cmd_vel last went out
  std::vector<Eigen::Vector2d> path_seen_;  // the global path /plan last carried
  std::optional<sim::Pose2> goal_seen_;     // the goal /goal_pose last carried
};

/// The QoS profile rosbag2 (Humble) stores as an MCAP channel's "offered_qos_profiles": a YAML list with one
/// profile, keep-last, reliable, automatic liveliness, infinite deadline, lifespan and lease; transient-local
/// with depth 1 when `latched` (so `ros2 bag play` hands /map to late subscribers), else volatile, depth 10.
std::string offered_qos_profiles_yaml(bool latched);

}  // namespace rfbsim::ros
