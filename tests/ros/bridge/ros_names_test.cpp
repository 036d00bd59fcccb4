// SPDX-License-Identifier: GPL-2.0-or-later
// ROS type and topic names in both spellings, the hub's namespace, and ws:// / wss:// URLs.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "ros/bridge/ros_names.hpp"
#include "ros/bridge/ws_url.hpp"

using namespace rfbsim::ros;

TEST_CASE("normalize_ros_type accepts pkg/Type and pkg/msg/Type and refuses the rest") {
  CHECK(normalize_ros_type("geometry_msgs/Twist") == "geometry_msgs/msg/Twist");
  CHECK(normalize_ros_type("geometry_msgs/msg/Twist") == "geometry_msgs/msg/Twist");
  CHECK(normalize_ros_type("sensor_msgs/LaserScan") == "sensor_msgs/msg/LaserScan");
  CHECK(normalize_ros_type("").empty());
  CHECK(normalize_ros_type("Twist").empty());
  CHECK(normalize_ros_type("geometry_msgs/srv/Twist").empty());
  CHECK(normalize_ros_type("geometry_msgs//Twist").empty());
  CHECK(normalize_ros_type("/geometry_msgs/Twist").empty());
  CHECK(normalize_ros_type("geometry_msgs/Twist/").empty());
  CHECK(normalize_ros_type("a/b/c/d").empty());
  CHECK(normalize_ros_type("geometry-msgs/Twist").empty());
  CHECK(normalize_ros_type("9pkg/Twist").empty());
  CHECK(short_ros_type("geometry_msgs/msg/Twist") == "geometry_msgs/Twist");
  CHECK(short_ros_type("geometry_msgs/Twist") == "geometry_msgs/Twist");
  CHECK(short_ros_type("nope").empty());
}

TEST_CASE("topics are made absolute and namespaces lose their trailing slash") {
  CHECK(normalize_topic("cmd_vel") == "/cmd_vel");
  CHECK(normalize_topic("/cmd_vel") == "/cmd_vel");
  CHECK(normalize_topic("/a/b_2") == "/a/b_2");
  CHECK_FALSE(normalize_topic(""));
  CHECK_FALSE(normalize_topic("/"));
  CHECK_FALSE(normalize_topic("/a//b"));
  CHECK_FALSE(normalize_topic("/a/"));
  CHECK_FALSE(normalize_topic("/a b"));
  CHECK_FALSE(normalize_topic("/2a"));
  CHECK(normalize_namespace("") == "");
  CHECK(normalize_namespace("/rfbsim/s1/") == "/rfbsim/s1");
  CHECK(normalize_namespace("/rfbsim/s1") == "/rfbsim/s1");
  CHECK_FALSE(normalize_namespace("rfbsim"));
  CHECK_FALSE(normalize_namespace("/"));
}

TEST_CASE("parse_ws_url splits ws and wss URLs and names the URL on every fault") {
  const WsUrl plain = parse_ws_url("ws://lab.example.org:9090/bridge?x=1");
  CHECK_FALSE(plain.tls);
  CHECK(plain.host == "lab.example.org");
  CHECK(plain.port == 9090);
  CHECK(plain.resource == "/bridge?x=1");
  const WsUrl secure = parse_ws_url("wss://lab.example.org");
  CHECK(secure.tls);
  CHECK(secure.port == 443);
  CHECK(secure.resource == "/");
  CHECK(parse_ws_url("ws://127.0.0.1").port == 80);
  const WsUrl v6 = parse_ws_url("ws://[::1]:9090");
  CHECK(v6.host == "::1");
  CHECK(v6.port == 9090);
  CHECK(parse_ws_url("ws://h?q").resource == "/?q");

  for (const char* bad : {"http://h/", "ws://", "ws://:9090/", "ws://u:p@h/", "ws://h:0/", "ws://h:65536/",
                          "ws://h:x/", "ws://h:/", "ws://h/#frag", "ws://h /", "ws://[::1/", "ws://[zz]/",
                          "ws://[::1]x/", "wss//h", "ws://h\x01/"}) {
    INFO(bad);
    try {
      parse_ws_url(bad);
      FAIL("accepted");
    } catch (const std::invalid_argument& error) {
      CHECK(std::string(error.what()).find(bad) != std::string::npos);
    }
  }
}
