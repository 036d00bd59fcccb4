// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeSession as pure protocol: each op's happy path and every kind of bad input, read back from the
// hub's queue. Bad input always gets an error status naming the problem and the op's id.
#include <catch2/catch.hpp>

#include <string>

#include "ros/bridge/rosbridge_link.hpp"
#include "ros/bridge/rosbridge_session.hpp"

using namespace rfbsim::ros;

namespace {

struct Fixture {
  RosbridgeHub hub{"/lab"};
  int connection = 0;
  RosbridgeSession session{hub, 0};

  Fixture() : connection(open()), session(hub, connection) {}

  int open() {
    hub.declare("/scan", "sensor_msgs/msg/LaserScan", false);
    hub.declare("/map", "nav_msgs/OccupancyGrid", true);
    hub.accept("/cmd_vel", {"geometry_msgs/Twist", "geometry_msgs/TwistStamped"});
    hub.accept("/events_in", {"std_msgs/String"});
    return hub.open_connection({});
  }

  // The frames the op produced, parsed.
  std::vector<nlohmann::json> send(const std::string& text) {
    session.on_text(text);
    std::vector<nlohmann::json> frames;
    for (const Frame& frame : hub.take_outgoing(connection, SIZE_MAX)) frames.push_back(nlohmann::json::parse(*frame));
    return frames;
  }

  // The one error status `text` gets; fails the test otherwise.
  std::string error_for(const std::string& text) {
    const auto frames = send(text);
    REQUIRE(frames.size() == 1);
    CHECK(frames[0]["op"] == "status");
    CHECK(frames[0]["level"] == "error");
    return frames[0]["msg"];
  }
};

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("subscribe takes both type spellings and refuses a type that differs from the declared one") {
  Fixture f;
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan","type":"sensor_msgs/LaserScan"})").empty());
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan","type":"sensor_msgs/msg/LaserScan","id":"b"})").empty());
  CHECK(f.hub.wanted("/scan"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","type":"std_msgs/String","id":"c"})"),
            "sensor_msgs/msg/LaserScan"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","type":"nonsense"})"), "malformed type"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/nope"})"), "no such topic"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/scan"})"), "no such topic"));  // outside the namespace
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/cmd_vel"})"), "published by clients"));
  CHECK(has(f.error_for(R"({"op":"subscribe"})"), "\"topic\""));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":7})"), "\"topic\""));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","throttle_rate":-5})"), "throttle_rate"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","throttle_rate":"fast"})"), "throttle_rate"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","queue_length":1.5})"), "queue_length"));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","compression":5})"), "compression"));
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan","throttle_rate":100.0,"queue_length":1,"fragment_size":1000})")
            .empty());
}

TEST_CASE("subscribe with a compression we do not speak gets a warning and plain JSON") {
  Fixture f;
  const auto frames = f.send(R"({"op":"subscribe","id":7,"topic":"/lab/scan","compression":"cbor"})");
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["level"] == "warning");
  CHECK(frames[0]["id"] == 7);  // integer ids are echoed as given
  f.hub.publish("/scan", {{"ranges", {1.0, 2.0}}});
  CHECK(f.send("{\"op\":\"status\",\"level\":\"info\",\"msg\":\"hi\"}").at(0)["op"] == "publish");
}

TEST_CASE("a latched topic's last message comes with the subscribe") {
  Fixture f;
  f.hub.publish("/map", {{"width", 3}});
  const auto frames = f.send(R"({"op":"subscribe","topic":"/lab/map"})");
  REQUIRE(frames.size() == 1);
  CHECK(frames[0] == nlohmann::json({{"op", "publish"}, {"topic", "/lab/map"}, {"msg", {{"width", 3}}}}));
}

TEST_CASE("publish on an accepted topic becomes an incoming message with the sender's type") {
  Fixture f;
  const nlohmann::json twist = {{"linear", {{"x", 0.2}, {"y", 0}, {"z", 0}}}, {"angular", {{"x", 0}, {"y", 0}, {"z", 0.5}}}};
  // Without advertise or "type", two accepted types leave the type open.
  CHECK(f.send(nlohmann::json({{"op", "publish"}, {"topic", "/lab/cmd_vel"}, {"msg", twist}}).dump()).empty());
  // advertise names it (short spelling accepted), and later publishes carry it.
  CHECK(f.send(R"({"op":"advertise","topic":"/lab/cmd_vel","type":"geometry_msgs/TwistStamped"})").empty());
  CHECK(f.send(nlohmann::json({{"op", "publish"}, {"topic", "/lab/cmd_vel"}, {"msg", twist}}).dump()).empty());
  // A "type" key on the publish wins.
  CHECK(f.send(nlohmann::json({{"op", "publish"}, {"topic", "/lab/cmd_vel"}, {"type", "geometry_msgs/msg/Twist"},
                               {"msg", twist}}).dump()).empty());
  // One accepted type: that one; a null "type" is no type, as on subscribe.
  CHECK(f.send(R"({"op":"publish","topic":"lab/events_in","msg":{"data":"x"}})").empty());
  CHECK(f.send(R"({"op":"publish","topic":"/lab/events_in","type":null,"msg":{"data":"y"}})").empty());
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan","type":null})").empty());
  const auto incoming = f.hub.take_incoming();
  REQUIRE(incoming.size() == 5);
  CHECK(incoming[4].type == "std_msgs/msg/String");
  CHECK(incoming[0].type.empty());
  CHECK(incoming[0].topic == "/cmd_vel");
  CHECK(incoming[0].msg == twist);
  CHECK(incoming[0].connection == f.connection);
  CHECK(incoming[1].type == "geometry_msgs/msg/TwistStamped");
  CHECK(incoming[2].type == "geometry_msgs/msg/Twist");
  CHECK(incoming[3].type == "std_msgs/msg/String");
  CHECK(incoming[3].topic == "/events_in");
}

TEST_CASE("bad publishes and advertises get an error status and change nothing") {
  Fixture f;
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/scan","msg":{}})"), "simulator only"));
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/unknown","msg":{},"id":"p1"})"), "takes nothing"));
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/cmd_vel"})"), "\"msg\""));
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/cmd_vel","msg":[1,2]})"), "\"msg\""));
  CHECK(has(f.error_for(R"({"op":"publish","msg":{}})"), "\"topic\""));
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/cmd_vel","type":"std_msgs/String","msg":{}})"),
            "geometry_msgs/msg/Twist"));
  CHECK(has(f.error_for(R"({"op":"publish","topic":"/lab/cmd_vel","type":3,"msg":{}})"), "type"));
  CHECK(has(f.error_for(R"({"op":"advertise","topic":"/lab/cmd_vel","type":"std_msgs/String"})"), "takes"));
  CHECK(has(f.error_for(R"({"op":"advertise","topic":"/lab/scan","type":"sensor_msgs/LaserScan"})"), "simulator only"));
  CHECK(has(f.error_for(R"({"op":"advertise","topic":"/lab/cmd_vel"})"), "\"type\""));
  CHECK(f.hub.take_incoming().empty());
  const auto warned = f.send(R"({"op":"unadvertise","topic":"/lab/cmd_vel"})");
  REQUIRE(warned.size() == 1);
  CHECK(warned[0]["level"] == "warning");
}

TEST_CASE("malformed frames and unknown ops get an error status with the id when one was readable") {
  Fixture f;
  CHECK(has(f.error_for("{not json"), "malformed JSON"));
  CHECK(has(f.error_for("[1,2,3]"), "JSON object"));
  CHECK(has(f.error_for("\"op\""), "JSON object"));
  CHECK(has(f.error_for("{}"), "\"op\""));
  CHECK(has(f.error_for(R"({"op":5})"), "\"op\""));
  CHECK(has(f.error_for(R"({"op":"subscribe","topic":"/lab/scan","id":{"a":1}})"), "\"id\""));
  CHECK(has(f.error_for(std::string(100, '[') + std::string(100, ']')), "deeper"));
  CHECK(has(f.error_for(std::string("{\"op\":\"x\xff\"}")), "malformed JSON"));
  const auto frames = f.send(R"({"op":"teleport","id":"t1"})");
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["id"] == "t1");
  CHECK(has(frames[0]["msg"], "unknown op 'teleport'"));
  CHECK(has(f.error_for(R"({"op":"fragment","id":"f","data":"x","num":0,"total":2})"), "not supported"));
  f.session.on_binary();
  CHECK(has(nlohmann::json::parse(*f.hub.take_outgoing(f.connection, SIZE_MAX).at(0))["msg"], "binary"));
}

TEST_CASE("call_service answers rosapi from the hub and any other service with a failed service_response") {
  Fixture f;
  const auto topics = f.send(R"({"op":"call_service","id":"c1","service":"/rosapi/topics","args":{}})");
  REQUIRE(topics.size() == 1);
  CHECK(topics[0]["op"] == "service_response");
  CHECK(topics[0]["result"] == true);
  CHECK(topics[0]["id"] == "c1");
  CHECK(topics[0]["service"] == "/rosapi/topics");
  // Namespaced topics, the accepted ones with their preferred type; the service name itself is not namespaced.
  CHECK(topics[0]["values"]["topics"] == nlohmann::json({"/lab/scan", "/lab/map", "/lab/cmd_vel", "/lab/events_in"}));
  CHECK(topics[0]["values"]["types"] == nlohmann::json({"sensor_msgs/msg/LaserScan", "nav_msgs/msg/OccupancyGrid",
                                                        "geometry_msgs/msg/Twist", "std_msgs/msg/String"}));

  const auto other = f.send(R"({"op":"call_service","id":7,"service":"/lab/rosapi/topics"})");
  REQUIRE(other.size() == 1);
  CHECK(other[0]["result"] == false);
  CHECK(other[0]["id"] == 7);
  CHECK(has(other[0]["values"].get<std::string>(), "/lab/rosapi/topics"));
  CHECK(has(f.error_for(R"({"op":"call_service"})"), "\"service\""));

  // A malformed request gets a failed response naming what is wrong, never an exception.
  const auto bad = f.send(R"({"op":"call_service","service":"/rosapi/topic_type","args":{"topic":5}})");
  REQUIRE(bad.size() == 1);
  CHECK(bad[0]["result"] == false);
  CHECK(has(bad[0]["values"].get<std::string>(), "\"topic\""));
  CHECK(f.send(R"({"op":"call_service","service":"/rosapi/topics","args":3})").at(0)["result"] == false);
  // rosbridge's positional args work too.
  const auto positional = f.send(R"({"op":"call_service","service":"/rosapi/topic_type","args":["/lab/map"]})");
  CHECK(positional.at(0)["values"]["type"] == "nav_msgs/msg/OccupancyGrid");
}

TEST_CASE("call_service finds rosapi with or without the leading slash, as roslibjs's helpers call it") {
  Fixture f;
  const auto relative = f.send(R"({"op":"call_service","id":"r","service":"rosapi/nodes","args":{}})");
  REQUIRE(relative.size() == 1);
  CHECK(relative[0]["result"] == true);
  CHECK(relative[0]["service"] == "rosapi/nodes");  // echoed as the client wrote it
  CHECK(relative[0]["values"]["nodes"] == nlohmann::json({"/rfbsim"}));
  const auto type =
      f.send(R"({"op":"call_service","id":"t","service":"rosapi/topic_type","args":{"topic":"/lab/map"}})");
  CHECK(type.at(0)["values"]["type"] == "nav_msgs/msg/OccupancyGrid");
  // A malformed or unknown name, relative or not, still gets a failed response naming it.
  for (const char* name : {"rosapi/get_param", "rosapi//topics", "", "rosapi/topics/"}) {
    const auto failed = f.send(nlohmann::json({{"op", "call_service"}, {"id", "x"}, {"service", name}}).dump());
    REQUIRE(failed.size() == 1);
    CHECK(failed[0]["op"] == "service_response");
    CHECK(failed[0]["result"] == false);
    CHECK(failed[0]["id"] == "x");
  }
}

TEST_CASE("send_action_goal gets a failed action_result at once, with the goal's id and the reason") {
  Fixture f;
  const auto frames = f.send(R"({"op":"send_action_goal","id":"g1","action":"/navigate_to_pose",)"
                             R"("action_type":"nav2_msgs/NavigateToPose","args":{},"feedback":true})");
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["op"] == "action_result");
  CHECK(frames[0]["id"] == "g1");
  CHECK(frames[0]["action"] == "/navigate_to_pose");
  CHECK(frames[0]["result"] == false);
  CHECK(frames[0]["status"] == 6);  // action_msgs/GoalStatus STATUS_ABORTED
  CHECK(has(frames[0]["values"].get<std::string>(), "/navigate_to_pose"));
  // Without an action or an id it still answers, and the connection stays usable.
  CHECK(f.send(R"({"op":"send_action_goal"})").at(0)["result"] == false);
  CHECK(has(f.error_for(R"({"op":"cancel_action_goal","id":"g1"})"), "not supported"));
}

TEST_CASE("set_level changes which status messages come back") {
  Fixture f;
  CHECK(f.send(R"({"op":"set_level","level":"info"})").empty());
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan"})").at(0)["level"] == "info");
  CHECK(has(f.error_for(R"({"op":"set_level","level":"loud"})"), "level"));
  CHECK(f.send(R"({"op":"set_level","level":"none"})").empty());
  CHECK(f.send(R"({"op":"bogus"})").empty());
  CHECK(f.send(R"({"op":"set_level","level":"error"})").empty());
  CHECK(f.error_for(R"({"op":"bogus"})") == "unknown op 'bogus'");
}

TEST_CASE("unsubscribe by id removes one subscription, without an id all of them") {
  Fixture f;
  f.send(R"({"op":"subscribe","topic":"/lab/scan","id":"a"})");
  f.send(R"({"op":"subscribe","topic":"/lab/scan","id":"b"})");
  CHECK(f.send(R"({"op":"unsubscribe","topic":"/lab/scan","id":"a"})").empty());
  CHECK(f.hub.wanted("/scan"));
  CHECK(f.send(R"({"op":"unsubscribe","topic":"/lab/scan"})").empty());
  CHECK_FALSE(f.hub.wanted("/scan"));
  CHECK(f.send(R"({"op":"unsubscribe","topic":"/lab/scan"})").at(0)["level"] == "warning");
}

TEST_CASE("the dial-out link greets with advertise and subscribe, and takes the server's publishes") {
  RosbridgeHub hub("/rfbsim/s1");
  hub.declare("/map", "nav_msgs/msg/OccupancyGrid", true);
  hub.declare("/odom", "nav_msgs/Odometry", false);
  hub.accept("/cmd_vel", {"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"});
  std::vector<std::string> log;
  RosbridgeLink link(hub, [&log](const std::string& line) { log.push_back(line); });
  std::vector<nlohmann::json> greeting;
  for (const std::string& op : link.greeting()) greeting.push_back(nlohmann::json::parse(op));
  REQUIRE(greeting.size() == 3);
  CHECK(greeting[0] == nlohmann::json({{"op", "advertise"}, {"id", "rfbsim_advertise:/map"},
                                       {"topic", "/rfbsim/s1/map"}, {"type", "nav_msgs/OccupancyGrid"},
                                       {"latch", true}}));
  CHECK_FALSE(greeting[1].contains("latch"));
  CHECK(greeting[2] == nlohmann::json({{"op", "subscribe"}, {"id", "rfbsim_subscribe:/cmd_vel"},
                                       {"topic", "/rfbsim/s1/cmd_vel"}, {"type", "geometry_msgs/Twist"}}));

  const int connection = hub.open_connection({});
  link.on_text(connection, R"({"op":"publish","topic":"/rfbsim/s1/cmd_vel","msg":{"linear":{"x":1}}})");
  link.on_text(connection, R"({"op":"publish","topic":"/other","msg":{}})");
  link.on_text(connection, "garbage");
  link.on_text(connection, R"({"op":"status","level":"error","msg":"no such type"})");
  link.on_text(connection, R"({"op":"status","level":7})");
  link.on_text(connection, R"({"op":"call_service","id":3,"service":"/x"})");
  const auto incoming = hub.take_incoming();
  REQUIRE(incoming.size() == 1);
  CHECK(incoming[0].topic == "/cmd_vel");
  CHECK(incoming[0].type == "geometry_msgs/msg/Twist");
  CHECK(log.size() == 3);
  const auto reply = nlohmann::json::parse(*hub.take_outgoing(connection, SIZE_MAX).at(0));
  CHECK(reply["op"] == "service_response");
  CHECK(reply["id"] == 3);
}

TEST_CASE("a subscribe beyond the per-topic cap gets an error status naming the cap, and is not added") {
  Fixture f;
  for (std::size_t n = 0; n < RosbridgeHub::kMaxIdsPerTopic; ++n) {
    CHECK(f.send(nlohmann::json({{"op", "subscribe"}, {"topic", "/lab/scan"}, {"id", n}}).dump()).empty());
  }
  const auto refused = f.send(R"({"op":"subscribe","topic":"/lab/scan","id":"one too many"})");
  REQUIRE(refused.size() == 1);
  CHECK(refused[0]["level"] == "error");
  CHECK(refused[0]["id"] == "one too many");
  CHECK(has(refused[0]["msg"], "32 subscriptions"));
  CHECK(f.send(R"({"op":"unsubscribe","topic":"/lab/scan","id":"one too many"})").at(0)["level"] == "warning");
}

TEST_CASE("a queue_length over the hub's limit is cut with a warning, one at the limit silently") {
  Fixture f;
  const std::string limit = std::to_string(RosbridgeHub::kMaxQueueLength);
  CHECK(f.send(R"({"op":"subscribe","topic":"/lab/scan","id":"a","throttle_rate":1000,"queue_length":)" + limit + "}")
            .empty());
  const auto warned =
      f.send(R"({"op":"subscribe","topic":"/lab/scan","id":"b","throttle_rate":1000,"queue_length":2000000000})");
  REQUIRE(warned.size() == 1);
  CHECK(warned[0]["level"] == "warning");
  CHECK(warned[0]["id"] == "b");
  CHECK(has(warned[0]["msg"], "queue_length 2000000000 is over the limit; " + limit + " is used"));
}

TEST_CASE("a published message moves whole to the simulation: its fields, its type and its connection") {
  Fixture f;
  CHECK(f.send(R"({"op":"publish","topic":"/lab/cmd_vel","msg":{"linear":{"x":0.5},"angular":{"z":[1,2]}}})").empty());
  const auto incoming = f.hub.take_incoming();
  REQUIRE(incoming.size() == 1);
  CHECK(incoming[0].msg == nlohmann::json({{"linear", {{"x", 0.5}}}, {"angular", {{"z", {1, 2}}}}}));
  CHECK(incoming[0].type.empty());  // two accepted types and none named
  CHECK(incoming[0].connection == f.connection);
}

TEST_CASE("the oversized-message status is built for sending at once, and honours the level") {
  Fixture f;
  RosbridgeSession session(f.hub, f.connection);
  const auto status = session.oversized_status(2000, 1000);
  REQUIRE(status);
  const auto parsed = nlohmann::json::parse(*status);
  CHECK(parsed["level"] == "error");
  CHECK(has(parsed["msg"], "2000 bytes is over the limit of 1000"));
  CHECK_FALSE(f.hub.has_outgoing(f.connection));  // not queued
  f.send(R"({"op":"set_level","level":"none"})");
  CHECK_FALSE(session.oversized_status(2000, 1000));
}
