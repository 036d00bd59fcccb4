// SPDX-License-Identifier: GPL-2.0-or-later
// ros_msgs_samples: prints one JSON line per sample message, {"name", "type", "schema", "cdr" (hex), "json"}:
// hand-made messages of every type (odd values: negative cells, NaN and infinite ranges, UTF-8, empty and
// long sequences) and the first message of each topic from a short real simulation. ros_msgs_decode.mjs
// parses each schema and decodes each CDR with the npm ROS 2 readers and compares with "json".
#include <cstdio>
#include <iostream>
#include <limits>
#include <set>
#include <string>

#include "app/simulation.hpp"
#include "ros/msgs/ros_cdr.hpp"
#include "ros/msgs/ros_json.hpp"
#include "ros/msgs/ros_schemas.hpp"
#include "ros/msgs/ros_topics.hpp"

namespace ros = rfbsim::ros;
namespace sim = rfbsim::sim;

namespace {

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  out.reserve(2 * bytes.size());
  for (std::uint8_t b : bytes) {
    out.push_back(digits[b >> 4]);
    out.push_back(digits[b & 15]);
  }
  return out;
}

void print(const std::string& name, std::string_view type, const std::vector<std::uint8_t>& cdr,
           const nlohmann::json& json) {
  const nlohmann::json line = {{"name", name},
                               {"type", std::string(type)},
                               {"schema", ros::ros2msg_schema(type)},
                               {"cdr", hex(cdr)},
                               {"json", json}};
  std::cout << line.dump() << '\n';
}

void print(const std::string& name, const ros::RosPayload& payload) {
  print(name, ros::ros_type_name(payload), ros::to_cdr(payload), ros::to_json(payload));
}

void hand_made() {
  const ros::Header header{{12, 345'678'901u}, "base_link"};
  print("clock", ros::Clock{{1, 2}});
  ros::TFMessage tf;
  tf.transforms.push_back({{{3, 4}, "map"}, "odom", {{1.5, -2.0, 0.0}, {0.0, 0.0, 0.38268343236, 0.92387953251}}});
  tf.transforms.push_back({header, "person_12", {{0.1, 0.2, 0.0}, {}}});
  print("tf", tf);
  print("tf empty", ros::TFMessage{});
  ros::Odometry odom;
  odom.header = {{5, 6}, "odom"};
  odom.child_frame_id = "base_link";
  odom.pose.pose.position = {1.0, 2.0, 0.0};
  for (int i = 0; i < 36; ++i) odom.pose.covariance[static_cast<std::size_t>(i)] = i * 0.5;
  odom.twist.twist.linear.x = 0.3;
  odom.twist.covariance[0] = 1e-9;
  print("odom", odom);
  ros::LaserScan scan;
  scan.header = header;
  scan.angle_min = -3.14159265f;
  scan.angle_increment = 0.0174532925f;
  scan.angle_max = scan.angle_min + 4 * scan.angle_increment;
  scan.scan_time = 0.1f;
  scan.range_min = 0.12f;
  scan.range_max = 8.0f;
  scan.ranges = {0.5f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 8.0f,
                 0.12f};
  scan.intensities = {1.0f, 0.0f};
  print("scan", scan);
  ros::OccupancyGrid grid;
  grid.header = {{0, 0}, "map"};
  grid.info.resolution = 0.05f;
  grid.info.width = 3;
  grid.info.height = 2;
  grid.info.origin.position = {-1.0, -2.0, 0.0};
  grid.data = {0, 100, -1, 0, 0, 100};
  print("map", grid);
  ros::Twist twist;
  twist.linear.x = 0.25;
  twist.angular.z = -0.5;
  print("cmd_vel", twist);
  ros::TwistStamped stamped{header, twist};
  print("cmd_vel stamped", ros::TwistStamped::kType, ros::to_cdr(stamped), ros::to_json(stamped));
  ros::People people;
  people.header = {{7, 8}, "map"};
  people.people.push_back({"person_1", {1, 2, 0}, {0.5, -0.25, 0}, 1.0, {}, {}});
  people.people.push_back({"avatar", {3, 4, 0}, {0, 1.2, 0}, 0.75, {"kind", "é"}, {"participant", "naïve"}});
  print("people", people);
  ros::Path path;
  path.header = {{9, 10}, "map"};
  for (int i = 0; i < 3; ++i) path.poses.push_back({{{9, 10}, "map"}, {{i * 1.0, 2.0, 0.0}, {}}});
  print("plan", path);
  ros::MarkerArray markers;
  ros::Marker cube;
  cube.header = {{0, 0}, "map"};
  cube.ns = "props";
  cube.id = 4;
  cube.type = ros::Marker::kCube;
  cube.pose.position = {1, 2, 0.4};
  cube.scale = {0.6, 0.4, 0.8};
  cube.color = {0.2f, 0.4f, 0.6f, 1.0f};
  cube.lifetime = {1, 500};
  cube.frame_locked = true;
  cube.points = {{1, 2, 3}};
  cube.colors = {{1, 0, 0, 1}};
  cube.text = "crate";
  markers.markers.push_back(cube);
  ros::Marker disc;
  disc.ns = "landmarks";
  disc.type = ros::Marker::kCylinder;
  disc.mesh_use_embedded_materials = true;
  markers.markers.push_back(disc);
  print("markers", markers);
  print("event", ros::String{R"({"t":1.5,"type":"task","detail":"reached the goal — ✓"})"});
  print("goal", ros::PoseStamped{{{0, 0}, "map"}, {{6.5, 1.5, 0.0}, {0, 0, 0.7071067811865476, 0.7071067811865476}}});
}

// The first message of each topic from two seconds of a small simulation with a robot, the crowd and the avatar.
void sampled() {
  sim::World world;
  world.map = sim::walled_grid(8.0, 6.0, 0.1);
  world.props = {{4.0, 4.5, 0.6, 0.4, 0.8, 0x336699, 0.3}};
  world.landmarks = {{"goal", 7.0, 5.0, 0.3, 0xf2c12e}};
  world.obstacles = sim::with_props_blocked(world.map, world.props);
  world.avatar.pose = {6.0, 0.8, 1.5707963267948966};
  sim::Robot robot;
  robot.pose = robot.estimate = {1.5, 1.5, 0.0};
  world.robot = robot;
  sim::RobotSetup setup;
  setup.mission.kind = sim::MissionSpec::Kind::GoTo;
  setup.mission.waypoints = {{6.5, 1.5, 0.0}};
  setup.mission.waypoint_names = {""};
  sim::CrowdSpec crowd;
  crowd.count = 2;
  sim::Simulation simulation(sim::SimulationParams{}, std::move(world), crowd, setup);
  simulation.apply_key(0x77, true);
  ros::RosWorldSampler sampler({60, 30});
  std::vector<ros::RosMessage> out;
  std::set<std::string> seen;
  for (int tick = 0; tick <= 120; ++tick) {
    if (tick > 0) simulation.step();
    out.clear();
    sampler.sample(simulation.world(), simulation.robot_stack(), out);
    if (tick == 1) sampler.add_event(ros::tick_time_ns(1, 60), R"({"type":"start"})", out);
    for (const auto& message : out) {
      if (seen.insert(message.topic->name).second) print("sampled " + message.topic->name, message.payload);
    }
  }
}

}  // namespace

int main() {
  try {
    hand_made();
    sampled();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros_msgs_samples: %s\n", e.what());
    return 1;
  }
  return 0;
}
