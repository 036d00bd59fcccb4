// SPDX-License-Identifier: GPL-2.0-or-later
// ros2msg schemas as rosbag2's MCAP storage lays them out: the root's .msg text first, then each nested type
// once, depth first in name order, after a line of 80 '=' and "MSG: pkg/Type"; and the QoS profile text.
#include <catch2/catch.hpp>

#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "ros/msgs/ros_schemas.hpp"
#include "ros/msgs/ros_topics.hpp"

namespace ros = rfbsim::ros;

namespace {

const std::string kRule(80, '=');

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The names after "MSG: ", in order.
std::vector<std::string> nested_names(const std::string& schema) {
  std::vector<std::string> names;
  for (const std::string& line : lines_of(schema)) {
    if (line.rfind("MSG: ", 0) == 0) names.push_back(line.substr(5));
  }
  return names;
}

}  // namespace

TEST_CASE("ros msgs: a Clock's schema is its .msg, then builtin_interfaces/Time after the rule", "[ros]") {
  CHECK(ros::ros2msg_schema("rosgraph_msgs/msg/Clock") ==
        "builtin_interfaces/Time clock\n\n" + kRule + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n");
  // Both spellings of a type name give the same text.
  CHECK(ros::ros2msg_schema("rosgraph_msgs/Clock") == ros::ros2msg_schema("rosgraph_msgs/msg/Clock"));
  CHECK(ros::ros2msg_schema("std_msgs/String") == "string data\n");
}

TEST_CASE("ros msgs: nested types come once each, depth first in name order", "[ros]") {
  CHECK(nested_names(ros::ros2msg_schema("nav_msgs/msg/Odometry")) ==
        std::vector<std::string>{"geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose", "geometry_msgs/Point",
                                 "geometry_msgs/Quaternion", "geometry_msgs/TwistWithCovariance",
                                 "geometry_msgs/Twist", "geometry_msgs/Vector3", "std_msgs/Header",
                                 "builtin_interfaces/Time"});
  // Unqualified names in a .msg belong to its own package: MarkerArray's "Marker[] markers".
  const auto markers = nested_names(ros::ros2msg_schema("visualization_msgs/MarkerArray"));
  REQUIRE_FALSE(markers.empty());
  CHECK(markers.front() == "visualization_msgs/Marker");
  CHECK(std::set<std::string>(markers.begin(), markers.end()).size() == markers.size());
}

TEST_CASE("ros msgs: every published type has a schema whose rules are exactly 80 '='", "[ros]") {
  for (const ros::TopicSpec& topic : ros::ros_topics()) {
    INFO(topic.type);
    const std::string schema = ros::ros2msg_schema(topic.type);
    const auto lines = lines_of(schema);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].find('=') == std::string::npos || lines[i].find(' ') != std::string::npos) continue;
      CHECK(lines[i] == kRule);
      REQUIRE(i + 1 < lines.size());
      CHECK(lines[i + 1].rfind("MSG: ", 0) == 0);
      CHECK(lines[i + 1].find("/msg/") == std::string::npos);
    }
  }
  CHECK_NOTHROW(ros::ros2msg_schema("geometry_msgs/TwistStamped"));
}

TEST_CASE("ros msgs: Marker is Humble's, constants kept, no Jazzy fields", "[ros]") {
  const std::string marker = ros::ros2msg_schema("visualization_msgs/MarkerArray");
  CHECK(marker.find("int32 ARROW=0\n") != std::string::npos);
  CHECK(marker.find("int32 CYLINDER=3\n") != std::string::npos);
  CHECK(marker.find("int32 DELETEALL=3\n") != std::string::npos);
  CHECK(marker.find("bool mesh_use_embedded_materials\n") != std::string::npos);
  CHECK(marker.find("texture") == std::string::npos);
  CHECK(marker.find("mesh_file") == std::string::npos);
  CHECK(marker.find("ARROW_STRIP") == std::string::npos);
}

TEST_CASE("ros msgs: an unknown type is refused by name", "[ros]") {
  CHECK_THROWS_WITH(ros::ros2msg_schema("sensor_msgs/msg/Image"), Catch::Contains("'sensor_msgs/msg/Image'"));
  CHECK_THROWS_AS(ros::ros2msg_schema(""), std::invalid_argument);
  CHECK_THROWS_AS(ros::ros2msg_schema("Clock"), std::invalid_argument);
  CHECK_THROWS_AS(ros::ros2msg_schema("rosgraph_msgs/msg/Clock/msg/x"), std::invalid_argument);
}

TEST_CASE("ros msgs: the QoS profiles are rosbag2 Humble's YAML, transient-local for latched topics", "[ros]") {
  const std::string volatile_yaml = ros::offered_qos_profiles_yaml(false);
  CHECK(volatile_yaml ==
        "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n"
        "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  liveliness: 1\n"
        "  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  avoid_ros_namespace_conventions: false");
  // It is YAML a reader takes apart as rosbag2 does: a list of one profile.
  const YAML::Node latched = YAML::Load(ros::offered_qos_profiles_yaml(true));
  REQUIRE(latched.IsSequence());
  REQUIRE(latched.size() == 1);
  CHECK(latched[0]["durability"].as<int>() == 1);
  CHECK(latched[0]["depth"].as<int>() == 1);
  CHECK(latched[0]["reliability"].as<int>() == 1);
  CHECK(latched[0]["deadline"]["nsec"].as<std::uint64_t>() == 854775807u);
  CHECK_FALSE(latched[0]["avoid_ros_namespace_conventions"].as<bool>());
}

TEST_CASE("ros msgs: the topic table", "[ros]") {
  const auto& topics = ros::ros_topics();
  std::vector<std::string> names;
  for (const auto& topic : topics) names.push_back(topic.name);
  CHECK(names == std::vector<std::string>{"/clock", "/tf", "/odom", "/scan", "/map", "/scene_markers", "/cmd_vel",
                                          "/people", "/plan", "/goal_pose", "/events"});
  for (const auto& topic : topics) {
    INFO(topic.name);
    CHECK(topic.latched == (topic.name == "/map" || topic.name == "/scene_markers" || topic.name == "/goal_pose"));
  }
  REQUIRE(ros::find_ros_topic("/scan") != nullptr);
  CHECK(ros::find_ros_topic("/scan")->type == "sensor_msgs/msg/LaserScan");
  CHECK(ros::find_ros_topic("/nope") == nullptr);
}
