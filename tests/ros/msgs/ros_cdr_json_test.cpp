// SPDX-License-Identifier: GPL-2.0-or-later
// CDR bytes of small messages counted by hand (alignment after strings, fixed arrays without a length), the
// rosbridge JSON shape of each type, and /cmd_vel read from JSON: good commands and bad ones.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "ros/msgs/ros_cdr.hpp"
#include "ros/msgs/ros_json.hpp"

namespace ros = rfbsim::ros;
using nlohmann::json;

namespace {

using Bytes = std::vector<std::uint8_t>;

template <typename T>
T read_at(const Bytes& bytes, std::size_t offset) {
  T value{};
  REQUIRE(offset + sizeof(T) <= bytes.size());
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

std::vector<std::string> keys(const json& object) {
  std::vector<std::string> out;
  for (const auto& item : object.items()) out.push_back(item.key());
  std::sort(out.begin(), out.end());
  return out;
}

// A TwistStamped as rosbridge JSON: 0.2 m/s ahead, turning at 0.4 rad/s.
json stamped_twist_json() {
  return json::parse(
      R"({"header": {"stamp": {"sec": 1, "nanosec": 2}, "frame_id": "base_link"},
          "twist": {"linear": {"x": 0.2, "y": 0, "z": 0}, "angular": {"x": 0, "y": 0, "z": 0.4}}})");
}

}  // namespace

TEST_CASE("ros msgs: CDR of a Clock, a String and a Twist, byte for byte", "[ros]") {
  CHECK(ros::to_cdr(ros::RosPayload(ros::Clock{{7, 250'000'000u}})) ==
        Bytes{0, 1, 0, 0, 7, 0, 0, 0, 0x80, 0xb2, 0xe6, 0x0e});
  // A string counts its NUL.
  CHECK(ros::to_cdr(ros::String{"hi"}) == Bytes{0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0});
  ros::Twist twist;
  twist.linear.x = 0.5;
  twist.angular.z = -1.25;
  const Bytes bytes = ros::to_cdr(twist);
  REQUIRE(bytes.size() == 4 + 6 * 8);
  CHECK(read_at<double>(bytes, 4) == 0.5);
  CHECK(read_at<double>(bytes, 4 + 5 * 8) == -1.25);
}

TEST_CASE("ros msgs: CDR of an Odometry: strings, padding and both fixed covariances", "[ros]") {
  ros::Odometry odom;
  odom.header = {{1, 2}, "odom"};
  odom.child_frame_id = "base_link";
  odom.pose.pose.position.x = 3.0;
  odom.pose.covariance[35] = 0.25;
  odom.twist.twist.angular.z = 0.5;
  const Bytes bytes = ros::to_cdr(odom);
  // Offsets after the 4-byte header: stamp 0..8, "odom" 8..17, pad to 20, "base_link" 20..34, pad to 40, pose
  // 40..96, covariance 96..384 (no length: float64[36]), twist 384..432, covariance 432..720.
  REQUIRE(bytes.size() == 4 + 720);
  CHECK(read_at<std::uint32_t>(bytes, 4 + 8) == 5);
  CHECK(read_at<std::uint32_t>(bytes, 4 + 20) == 10);
  CHECK(read_at<double>(bytes, 4 + 40) == 3.0);
  CHECK(read_at<double>(bytes, 4 + 96 + 35 * 8) == 0.25);
  CHECK(read_at<double>(bytes, 4 + 384 + 5 * 8) == 0.5);
}

TEST_CASE("ros msgs: CDR of a LaserScan: float32 fields, then ranges and intensities as sequences", "[ros]") {
  ros::LaserScan scan;
  scan.header = {{0, 0}, "base_link"};
  scan.angle_min = -1.5f;
  scan.range_max = 8.0f;
  scan.ranges = {1.0f, std::numeric_limits<float>::infinity(), 2.5f};
  const Bytes bytes = ros::to_cdr(scan);
  // stamp 0..8, "base_link" 8..22, pad to 24, seven float32 24..52, ranges length 52, values 56..68,
  // intensities length 68..72.
  REQUIRE(bytes.size() == 4 + 72);
  CHECK(read_at<float>(bytes, 4 + 24) == -1.5f);
  CHECK(read_at<float>(bytes, 4 + 48) == 8.0f);
  CHECK(read_at<std::uint32_t>(bytes, 4 + 52) == 3);
  CHECK(read_at<float>(bytes, 4 + 64) == 2.5f);
  CHECK(read_at<std::uint32_t>(bytes, 4 + 68) == 0);
}

TEST_CASE("ros msgs: JSON has the .msg's field names, Time as sec and nanosec", "[ros]") {
  const json clock = ros::to_json(ros::Clock{{3, 500u}});
  CHECK(clock == json::parse(R"({"clock": {"sec": 3, "nanosec": 500}})"));

  ros::Odometry odom;
  odom.header = {{1, 2}, "odom"};
  const json o = ros::to_json(odom);
  CHECK(keys(o) == std::vector<std::string>{"child_frame_id", "header", "pose", "twist"});
  CHECK(o["header"]["stamp"] == json::parse(R"({"sec": 1, "nanosec": 2})"));
  CHECK(o["pose"]["covariance"].size() == 36);
  CHECK(o["pose"]["pose"]["orientation"]["w"] == 1.0);

  ros::TFMessage tf;
  tf.transforms.push_back({{{0, 0}, "map"}, "odom", {}});
  const json t = ros::to_json(tf);
  CHECK(keys(t["transforms"][0]) == std::vector<std::string>{"child_frame_id", "header", "transform"});
  CHECK(keys(t["transforms"][0]["transform"]) == std::vector<std::string>{"rotation", "translation"});
}

TEST_CASE("ros msgs: JSON of a LaserScan writes non-finite ranges as null", "[ros]") {
  ros::LaserScan scan;
  scan.ranges = {1.5f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()};
  const json s = ros::to_json(scan);
  REQUIRE(s["ranges"].size() == 3);
  CHECK(s["ranges"][0] == 1.5);
  CHECK(s["ranges"][1].is_null());
  CHECK(s["ranges"][2].is_null());
  CHECK(s["intensities"] == json::array());
  CHECK(s.dump().find("NaN") == std::string::npos);
}

TEST_CASE("ros msgs: JSON of an OccupancyGrid, People and a Marker", "[ros]") {
  ros::OccupancyGrid grid;
  grid.info.width = 3;
  grid.info.height = 1;
  grid.data = {0, 100, -1};
  const json g = ros::to_json(grid);
  CHECK(g["data"] == json::parse("[0, 100, -1]"));  // int8[]: numbers, not base64
  CHECK(keys(g["info"]) == std::vector<std::string>{"height", "map_load_time", "origin", "resolution", "width"});

  ros::People people;
  people.people.push_back({"avatar", {1, 2, 0}, {0.5, 0, 0}, 1.0, {}, {}});
  const json p = ros::to_json(people);
  CHECK(keys(p["people"][0]) ==
        std::vector<std::string>{"name", "position", "reliability", "tagnames", "tags", "velocity"});
  CHECK(p["people"][0]["name"] == "avatar");
  CHECK(p["people"][0]["tags"] == json::array());

  ros::MarkerArray markers;
  markers.markers.emplace_back();
  markers.markers[0].type = ros::Marker::kCylinder;
  const json m = ros::to_json(markers);
  CHECK(keys(m["markers"][0]) ==
        std::vector<std::string>{"action", "color", "colors", "frame_locked", "header", "id", "lifetime",
                                 "mesh_resource", "mesh_use_embedded_materials", "ns", "points", "pose", "scale",
                                 "text", "type"});
  CHECK(m["markers"][0]["type"] == 3);
  CHECK(m["markers"][0]["lifetime"] == json::parse(R"({"sec": 0, "nanosec": 0})"));
}

TEST_CASE("ros msgs: a Twist from JSON", "[ros]") {
  std::string error;
  const auto twist = ros::twist_from_json(json::parse(R"({"linear": {"x": 0.3}, "angular": {"z": -1}})"),
                                          "geometry_msgs/msg/Twist", error);
  REQUIRE(twist);
  CHECK(twist->linear.x == 0.3);
  CHECK(twist->angular.z == -1.0);
}

TEST_CASE("ros msgs: fields missing from a Twist in JSON are 0", "[ros]") {
  std::string error;
  auto twist = ros::twist_from_json(json::parse(R"({"linear": {"x": 0.3}, "angular": {"z": -1}})"),
                                    "geometry_msgs/msg/Twist", error);
  REQUIRE(twist);
  CHECK(twist->linear.y == 0.0);
  CHECK(twist->linear.z == 0.0);
  CHECK(twist->angular.x == 0.0);
  CHECK(twist->angular.y == 0.0);

  twist = ros::twist_from_json(json::object(), "geometry_msgs/Twist", error);
  REQUIRE(twist);
  CHECK(twist->linear.x == 0.0);
  CHECK(twist->angular.z == 0.0);
}

TEST_CASE("ros msgs: a TwistStamped from JSON", "[ros]") {
  std::string error;
  const auto twist = ros::twist_from_json(stamped_twist_json(), "geometry_msgs/msg/TwistStamped", error);
  REQUIRE(twist);
  CHECK(twist->linear.x == 0.2);
  CHECK(twist->angular.z == 0.4);
}

TEST_CASE("ros msgs: without a type, the \"twist\" key tells a TwistStamped from a Twist", "[ros]") {
  std::string error;
  auto twist = ros::twist_from_json(stamped_twist_json(), "", error);
  REQUIRE(twist);
  CHECK(twist->angular.z == 0.4);
  twist = ros::twist_from_json(json::parse(R"({"linear": {"x": 1}})"), "", error);
  REQUIRE(twist);
  CHECK(twist->linear.x == 1.0);
}

TEST_CASE("ros msgs: a bad /cmd_vel message is refused with the reason in words", "[ros]") {
  struct Bad {
    const char* msg;
    const char* type;
    const char* reason;
  };
  const std::vector<Bad> cases = {
      {R"({"linear": {"x": "fast"}})", "geometry_msgs/msg/Twist", "msg.linear.x: expected a number, got string"},
      {R"({"linear": {"x": true}})", "geometry_msgs/msg/Twist", "expected a number, got boolean"},
      {R"({"linear": [1, 2, 3]})", "geometry_msgs/msg/Twist", "msg.linear: expected an object"},
      {R"({"linear": {"w": 1}})", "geometry_msgs/msg/Twist", "has no field 'w'"},
      {R"({"speed": 1})", "geometry_msgs/msg/Twist", "geometry_msgs/Twist has no field 'speed'"},
      {R"([1, 2])", "geometry_msgs/msg/Twist", "msg: expected an object"},
      {R"(null)", "geometry_msgs/msg/TwistStamped", "msg: expected an object"},
      {R"({"twist": {"linear": {"x": null}}})", "geometry_msgs/msg/TwistStamped", "msg.twist.linear.x"},
      {R"({"header": {"frame_id": 5}})", "geometry_msgs/msg/TwistStamped", "msg.header.frame_id: expected a string"},
      {R"({"header": {"stamp": {"sec": 1.5}}})", "geometry_msgs/msg/TwistStamped", "expected an integer"},
      {R"({"linear": {}})", "std_msgs/msg/String", "is not a velocity command"},
  };
  for (const Bad& bad : cases) {
    INFO(bad.msg << " as " << bad.type);
    std::string error;
    const json msg = json::parse(bad.msg);
    CHECK_FALSE(ros::twist_from_json(msg, bad.type, error));
    CHECK_THAT(error, Catch::Contains(bad.reason));
  }
  // The parser refuses 1e999 itself (the bridge answers that); a message built in code can still hold infinity.
  json infinite = json::object();
  infinite["angular"]["z"] = std::numeric_limits<double>::infinity();
  std::string error;
  CHECK_FALSE(ros::twist_from_json(infinite, "geometry_msgs/msg/Twist", error));
  CHECK_THAT(error, Catch::Contains("msg.angular.z: not a finite number"));
}
