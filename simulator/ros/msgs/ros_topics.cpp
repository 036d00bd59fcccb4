// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/msgs/ros_topics.hpp"

#include <stdexcept>

namespace rfbsim::ros {

const std::vector<TopicSpec>& ros_topics() {
  static const std::vector<TopicSpec> topics = {
      {"/clock", std::string(Clock::kType), false},
      {"/tf", std::string(TFMessage::kType), false},
      {"/odom", std::string(Odometry::kType), false},
      {"/scan", std::string(LaserScan::kType), false},
      {"/map", std::string(OccupancyGrid::kType), true},
      {"/scene_markers", std::string(MarkerArray::kType), true},
      {"/cmd_vel", std::string(Twist::kType), false},
      {"/people", std::string(People::kType), false},
      {"/plan", std::string(Path::kType), false},
      {"/goal_pose", std::string(PoseStamped::kType), true},
      {"/events", std::string(String::kType), false},
  };
  return topics;
}

const TopicSpec* find_ros_topic(std::string_view name) {
  for (const TopicSpec& topic : ros_topics()) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

std::uint64_t tick_time_ns(std::uint64_t tick, int tick_hz) {
  if (tick_hz <= 0) throw std::invalid_argument("tick_time_ns: tick_hz must be positive");
  // Whole seconds and the remainder apart, so that tick * 1e9 cannot overflow however long the session.
  const auto hz = static_cast<std::uint64_t>(tick_hz);
  return tick / hz * 1'000'000'000ull + tick % hz * 1'000'000'000ull / hz;
}

std::string offered_qos_profiles_yaml(bool latched) {
  // Humble's rosbag2 writes the policies as rmw's enum numbers (history 1 keep-last, reliability 1 reliable,
  // durability 1 transient-local / 2 volatile, liveliness 1 automatic) and infinite durations as
  // RMW_DURATION_INFINITE {9223372036, 854775807}, in this key order, dumped by yaml-cpp without a final
  // newline (rosbag2_transport/qos.cpp, Humble). Jazzy's rosbag2 (bag metadata version 9) writes names
  // ("keep_last", "reliable") instead, and reads numbers only from bags of version 8 and older.
  const std::string infinite = "    sec: 9223372036\n    nsec: 854775807\n";
  return std::string("- history: 1\n") +
         "  depth: " + (latched ? "1" : "10") + "\n" +
         "  reliability: 1\n" +
         "  durability: " + (latched ? "1" : "2") + "\n" +
         "  deadline:\n" + infinite +
         "  lifespan:\n" + infinite +
         "  liveliness: 1\n" +
         "  liveliness_lease_duration:\n" + infinite +
         "  avoid_ros_namespace_conventions: false";
}

}  // namespace rfbsim::ros
