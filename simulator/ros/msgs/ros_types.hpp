// SPDX-License-Identifier: GPL-2.0-or-later
// The ROS 2 message types rfbsim publishes, as plain structs with the fields of their .msg files in the same
// order and with the same names. Definitions are ROS 2 Humble's (common_interfaces, rosgraph_msgs and the
// people repository's ros2 branch, as documented on docs.ros.org); Humble's visualization_msgs/Marker has none
// of the texture, uv_coordinates and mesh_file fields later distributions added. Units are ROS's (REP 103):
// metres, radians, seconds; frames are right-handed with z up, and rfbsim's floor plane is z = 0.
//
// Each top-level type names itself in kType ("pkg/msg/Type", as MCAP's ros2 profile and rosbridge's ROS 2
// form spell it). Schemas, CDR and JSON for these live beside this file.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace rfbsim::ros {

// ---- builtin_interfaces ----

/// builtin_interfaces/Time: a point in time since the epoch (for rfbsim: since the session began).
struct Time {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;  ///< 0 .. 999'999'999
};

/// builtin_interfaces/Duration: a span of time (0 = forever, for Marker::lifetime).
struct Duration {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
};

/// `ns` nanoseconds as a Time (seconds beyond int32 wrap as ROS's own conversion does; sessions are far shorter).
constexpr Time time_from_ns(std::uint64_t ns) {
  return {static_cast<std::int32_t>(ns / 1'000'000'000ull), static_cast<std::uint32_t>(ns % 1'000'000'000ull)};
}

// ---- std_msgs ----

/// std_msgs/Header: when the data was taken and the frame it is expressed in.
struct Header {
  Time stamp;
  std::string frame_id;
};

/// std_msgs/String.
struct String {
  static constexpr std::string_view kType = "std_msgs/msg/String";
  std::string data;
};

/// std_msgs/ColorRGBA: components in 0..1.
struct ColorRGBA {
  float r = 0.0f;
  float g = 0.0f;
  float b = 0.0f;
  float a = 0.0f;
};

// ---- geometry_msgs ----

/// geometry_msgs/Vector3.
struct Vector3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

/// geometry_msgs/Point.
struct Point {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

/// geometry_msgs/Quaternion (ROS 2's .msg gives w the default 1: the identity rotation).
struct Quaternion {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
  double w = 1.0;
};

/// geometry_msgs/Pose.
struct Pose {
  Point position;
  Quaternion orientation;
};

/// geometry_msgs/PoseStamped.
struct PoseStamped {
  static constexpr std::string_view kType = "geometry_msgs/msg/PoseStamped";
  Header header;
  Pose pose;
};

/// geometry_msgs/Twist: m/s and rad/s.
struct Twist {
  static constexpr std::string_view kType = "geometry_msgs/msg/Twist";
  Vector3 linear;
  Vector3 angular;
};

/// geometry_msgs/TwistStamped.
struct TwistStamped {
  static constexpr std::string_view kType = "geometry_msgs/msg/TwistStamped";
  Header header;
  Twist twist;
};

/// geometry_msgs/Transform.
struct Transform {
  Vector3 translation;
  Quaternion rotation;
};

/// geometry_msgs/TransformStamped: the pose of child_frame_id in header.frame_id.
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Transform transform;
};

/// geometry_msgs/PoseWithCovariance: covariance row-major over (x, y, z, rot x, rot y, rot z).
struct PoseWithCovariance {
  Pose pose;
  std::array<double, 36> covariance{};
};

/// geometry_msgs/TwistWithCovariance.
struct TwistWithCovariance {
  Twist twist;
  std::array<double, 36> covariance{};
};

// ---- tf2_msgs, rosgraph_msgs ----

/// tf2_msgs/TFMessage: what /tf carries.
struct TFMessage {
  static constexpr std::string_view kType = "tf2_msgs/msg/TFMessage";
  std::vector<TransformStamped> transforms;
};

/// rosgraph_msgs/Clock: the simulated time, for nodes with use_sim_time.
struct Clock {
  static constexpr std::string_view kType = "rosgraph_msgs/msg/Clock";
  Time clock;
};

// ---- nav_msgs ----

/// nav_msgs/Odometry: pose in header.frame_id, twist in child_frame_id.
struct Odometry {
  static constexpr std::string_view kType = "nav_msgs/msg/Odometry";
  Header header;
  std::string child_frame_id;
  PoseWithCovariance pose;
  TwistWithCovariance twist;
};

/// nav_msgs/MapMetaData.
struct MapMetaData {
  Time map_load_time;
  float resolution = 0.0f;  ///< m per cell
  std::uint32_t width = 0;  ///< cells
  std::uint32_t height = 0;
  Pose origin;  ///< the pose of cell (0, 0)'s lower-left corner in the map frame
};

/// nav_msgs/OccupancyGrid: row-major from the bottom row; 0 free, 100 occupied, -1 unknown.
struct OccupancyGrid {
  static constexpr std::string_view kType = "nav_msgs/msg/OccupancyGrid";
  Header header;
  MapMetaData info;
  std::vector<std::int8_t> data;
};

/// nav_msgs/Path.
struct Path {
  static constexpr std::string_view kType = "nav_msgs/msg/Path";
  Header header;
  std::vector<PoseStamped> poses;
};

// ---- sensor_msgs ----

/// sensor_msgs/LaserScan: angles in rad about the frame's z, counter-clockwise from its x.
struct LaserScan {
  static constexpr std::string_view kType = "sensor_msgs/msg/LaserScan";
  Header header;
  float angle_min = 0.0f;
  float angle_max = 0.0f;
  float angle_increment = 0.0f;
  float time_increment = 0.0f;  ///< s between beams
  float scan_time = 0.0f;       ///< s between sweeps
  float range_min = 0.0f;       ///< m
  float range_max = 0.0f;       ///< m
  std::vector<float> ranges;
  std::vector<float> intensities;
};

// ---- people_msgs (the people repository, ros2 branch) ----

/// people_msgs/Person: a tracked person; velocity is a Point by the message's own choice.
struct Person {
  std::string name;
  Point position;
  Point velocity;  ///< m/s
  double reliability = 0.0;
  std::vector<std::string> tagnames;
  std::vector<std::string> tags;
};

/// people_msgs/People.
struct People {
  static constexpr std::string_view kType = "people_msgs/msg/People";
  Header header;
  std::vector<Person> people;
};

// ---- visualization_msgs (Humble) ----

/// visualization_msgs/Marker as in ROS 2 Humble.
struct Marker {
  // The .msg's constants (those rfbsim uses).
  static constexpr std::int32_t kCube = 1;
  static constexpr std::int32_t kCylinder = 3;
  static constexpr std::int32_t kAdd = 0;

  Header header;
  std::string ns;
  std::int32_t id = 0;
  std::int32_t type = 0;
  std::int32_t action = kAdd;
  Pose pose;
  Vector3 scale;
  ColorRGBA color;
  Duration lifetime;  ///< 0 = forever
  bool frame_locked = false;
  std::vector<Point> points;
  std::vector<ColorRGBA> colors;
  std::string text;
  std::string mesh_resource;
  bool mesh_use_embedded_materials = false;
};

/// visualization_msgs/MarkerArray.
struct MarkerArray {
  static constexpr std::string_view kType = "visualization_msgs/msg/MarkerArray";
  std::vector<Marker> markers;
};

/// One message of any top-level type rfbsim publishes.
using RosPayload = std::variant<Clock, TFMessage, Odometry, LaserScan, OccupancyGrid, Twist, People, Path,
                                MarkerArray, String, PoseStamped>;

/// The payload's type name, "pkg/msg/Type".
inline std::string_view ros_type_name(const RosPayload& payload) {
  return std::visit([](const auto& message) { return std::decay_t<decltype(message)>::kType; }, payload);
}

}  // namespace rfbsim::ros
