// SPDX-License-Identifier: GPL-2.0-or-later
// rosapi discovery over a real RosbridgeServer on loopback, as Foxglove, Lichtblick and roslibjs call it:
// each service's service_response read back by a real WebSocket client, under a topic namespace.
#include <catch2/catch.hpp>

#include <algorithm>
#include <memory>
#include <string>

#include "ros/bridge/rosapi_services.hpp"
#include "ros/bridge/rosbridge_server.hpp"
#include "test_ws_client.hpp"

using namespace rfbsim::ros;
using rfbsim::test::TestWsClient;

namespace {

constexpr const char* kLaserScanText = "std_msgs/Header header\nfloat32 angle_min\n";  // a stand-in: any text
constexpr const char* kTwistText = "Vector3 linear\nVector3 angular\n";

struct Served {
  RosbridgeHub hub{"/rfbsim/s1"};
  std::unique_ptr<RosbridgeServer> server;
  std::unique_ptr<TestWsClient> client;

  Served() {
    hub.declare("/clock", "rosgraph_msgs/Clock", false);
    hub.declare("/scan", "sensor_msgs/msg/LaserScan", false);
    hub.declare("/map", "nav_msgs/msg/OccupancyGrid", true);
    hub.accept("/cmd_vel", {"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"});
    hub.set_definition("sensor_msgs/LaserScan", kLaserScanText);
    hub.set_definition("geometry_msgs/msg/Twist", kTwistText);
    server = std::make_unique<RosbridgeServer>(hub, RosbridgeServerOptions{});
    client = std::make_unique<TestWsClient>(server->port());
  }

  // Calls `service` with `args` and returns its service_response (fails the test when none comes).
  nlohmann::json call(const std::string& service, const nlohmann::json& args = nlohmann::json::object()) {
    const std::string id = "call:" + service;
    client->send_json({{"op", "call_service"}, {"id", id}, {"service", service}, {"args", args}});
    const auto response = client->wait_for([&](const nlohmann::json& value) {
      return value.value("op", "") == "service_response" && value.value("id", "") == id;
    });
    REQUIRE(response);
    CHECK((*response)["service"] == service);
    return *response;
  }

  // The values of a call that must succeed.
  nlohmann::json values(const std::string& service, const nlohmann::json& args = nlohmann::json::object()) {
    const nlohmann::json response = call(service, args);
    REQUIRE(response["result"] == true);
    return response["values"];
  }
};

}  // namespace

TEST_CASE("rosapi topics and topics_and_raw_types list the namespaced topics with their types and definitions") {
  Served s;
  const nlohmann::json topics = s.values("/rosapi/topics");
  const nlohmann::json expected_topics = {"/rfbsim/s1/clock", "/rfbsim/s1/scan", "/rfbsim/s1/map",
                                          "/rfbsim/s1/cmd_vel"};
  const nlohmann::json expected_types = {"rosgraph_msgs/msg/Clock", "sensor_msgs/msg/LaserScan",
                                         "nav_msgs/msg/OccupancyGrid", "geometry_msgs/msg/Twist"};
  CHECK(topics["topics"] == expected_topics);
  CHECK(topics["types"] == expected_types);
  CHECK_FALSE(topics.contains("typedefs_full_text"));

  const nlohmann::json raw = s.values("/rosapi/topics_and_raw_types");
  CHECK(raw["topics"] == expected_topics);
  CHECK(raw["types"] == expected_types);
  // One definition per topic, in the same order, as the hub was given them ("" where none was).
  CHECK(raw["typedefs_full_text"] == nlohmann::json({"", kLaserScanText, "", kTwistText}));
}

TEST_CASE("rosapi get_ros_version, nodes and services describe rfbsim's ROS 2 server") {
  Served s;
  const nlohmann::json version = s.values("/rosapi/get_ros_version");
  CHECK(version["version"] == 2);
  CHECK(version["distro"] == "humble");
  CHECK(s.values("/rosapi/nodes")["nodes"] == nlohmann::json({"/rfbsim"}));
  const nlohmann::json services = s.values("/rosapi/services")["services"];
  CHECK(services.size() == 10);
  for (const char* name : {"/rosapi/topics", "/rosapi/topics_and_raw_types", "/rosapi/get_ros_version",
                                  "/rosapi/get_time", "/rosapi/nodes", "/rosapi/services", "/rosapi/topic_type",
                                  "/rosapi/publishers", "/rosapi/subscribers", "/rosapi/message_details"}) {
    CHECK(std::find(services.begin(), services.end(), name) != services.end());
  }
}

TEST_CASE("rosapi message_details parses a topic type's definition into TypeDefs, and fails for others") {
  Served s;
  // Either spelling, an args object or rosbridge's positional list, and roslibjs's relative service name.
  for (const nlohmann::json& args : {nlohmann::json({{"type", "geometry_msgs/Twist"}}),
                                     nlohmann::json::array({"geometry_msgs/msg/Twist"})}) {
    const nlohmann::json typedefs = s.values("rosapi/message_details", args)["typedefs"];
    REQUIRE(typedefs.size() == 1);
    CHECK(typedefs[0]["type"] == "geometry_msgs/msg/Twist");
    CHECK(typedefs[0]["fieldnames"] == nlohmann::json({"linear", "angular"}));
    CHECK(typedefs[0]["fieldtypes"] == nlohmann::json({"geometry_msgs/msg/Vector3", "geometry_msgs/msg/Vector3"}));
    CHECK(typedefs[0]["fieldarraylen"] == nlohmann::json({-1, -1}));
  }
  for (const char* type : {"nav_msgs/msg/OccupancyGrid", "geometry_msgs/msg/Vector3", "nonsense"}) {
    const nlohmann::json failed = s.call("/rosapi/message_details", {{"type", type}});
    CHECK(failed["result"] == false);
    CHECK(failed["values"].get<std::string>().find(type) != std::string::npos);
  }
  CHECK(s.call("/rosapi/message_details", nlohmann::json::object())["result"] == false);
}

TEST_CASE("rosapi get_time answers the latest /clock the simulation published, zero before any") {
  Served s;
  const nlohmann::json zero = {{"sec", 0}, {"nanosec", 0}};
  CHECK(s.values("/rosapi/get_time")["time"] == zero);
  s.hub.publish("/clock", {{"clock", {{"sec", 3}, {"nanosec", 250000000}}}});
  s.hub.publish("/clock", {{"clock", {{"sec", 3}, {"nanosec", 300000000}}}});
  const nlohmann::json later = {{"sec", 3}, {"nanosec", 300000000}};
  CHECK(s.values("/rosapi/get_time")["time"] == later);
}

TEST_CASE("rosapi topic_type, publishers and subscribers answer per topic, empty for unknown topics") {
  Served s;
  CHECK(s.values("/rosapi/topic_type", {{"topic", "/rfbsim/s1/scan"}})["type"] == "sensor_msgs/msg/LaserScan");
  CHECK(s.values("/rosapi/topic_type", {{"topic", "/rfbsim/s1/cmd_vel"}})["type"] == "geometry_msgs/msg/Twist");
  CHECK(s.values("/rosapi/topic_type", {{"topic", "/scan"}})["type"] == "");  // outside the namespace
  CHECK(s.values("/rosapi/publishers", {{"topic", "/rfbsim/s1/scan"}})["publishers"] == nlohmann::json({"/rfbsim"}));
  CHECK(s.values("/rosapi/publishers", {{"topic", "/rfbsim/s1/cmd_vel"}})["publishers"] == nlohmann::json::array());
  CHECK(s.values("/rosapi/subscribers", {{"topic", "/rfbsim/s1/cmd_vel"}})["subscribers"] ==
        nlohmann::json({"/rfbsim"}));
  CHECK(s.values("/rosapi/subscribers", {{"topic", "/rfbsim/s1/map"}})["subscribers"] == nlohmann::json::array());
  CHECK(s.values("/rosapi/publishers", {{"topic", "/rfbsim/s1/nope"}})["publishers"] == nlohmann::json::array());

  const nlohmann::json missing = s.call("/rosapi/topic_type", nlohmann::json::object());
  CHECK(missing["result"] == false);
  CHECK(missing["values"].get<std::string>().find("\"topic\"") != std::string::npos);
}

TEST_CASE("an unknown or namespaced rosapi service gets a failed service_response and the connection stays open") {
  Served s;
  for (const char* name : {"/rosapi/get_param", "/rfbsim/s1/rosapi/topics", "/spawn"}) {
    const nlohmann::json response = s.call(name);
    CHECK(response["result"] == false);
    CHECK(response["values"].get<std::string>().find(name) != std::string::npos);
  }
  CHECK(s.values("/rosapi/nodes")["nodes"] == nlohmann::json({"/rfbsim"}));
}
