// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: RosbridgeSession, the rosbridge v2 server's reading of one client's ops
// (simulator/ros/bridge/rosbridge_session.*, with the hub and rosapi discovery behind it). The input is one
// text frame from a client of a namespaced hub with declared, latched and accepted topics; the simulation
// then publishes on every declared topic, so that whatever the op subscribed to is exercised too.
// Invariants: every frame queued for the client is a JSON object with a known op (status, publish or
// service_response) and the fields rosbridge's protocol gives it, a status within the hub's bound (the
// first 60 s found a malformed frame whose parse error quoted it 8-fold); every message that reaches the
// simulation is on an accepted topic, a JSON object, with an accepted type or none; the session's answers to
// an op stay bounded (a handful of frames).
#include <deque>
#include <string>

#include <nlohmann/json.hpp>

#include "fuzz_check.hpp"
#include "ros/bridge/rosbridge_hub.hpp"
#include "ros/bridge/rosbridge_session.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::ros;

namespace {

// The hub a sim_rfb bridge has, in small: a namespace, a latched topic with a message waiting, /clock.
void declare_topics(RosbridgeHub& hub) {
  hub.declare("/clock", "rosgraph_msgs/msg/Clock", false);
  hub.declare("/scan", "sensor_msgs/msg/LaserScan", false);
  hub.declare("/map", "nav_msgs/msg/OccupancyGrid", true);
  hub.accept("/cmd_vel", {"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"});
  hub.set_definition("geometry_msgs/msg/Twist", "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n");
  hub.publish("/map", {{"info", {{"width", 2}, {"height", 1}}}, {"data", {0, 100}}});
}

bool is_string_field(const nlohmann::json& frame, const char* name) {
  const auto field = frame.find(name);
  return field != frame.end() && field->is_string();
}

// A frame the server may send: its op and the fields that op carries (ROSBRIDGE_PROTOCOL.md).
void check_frame(const std::string& text) {
  const nlohmann::json frame = nlohmann::json::parse(text, nullptr, false);
  check(frame.is_object(), "outgoing frame is not a JSON object");
  check(is_string_field(frame, "op"), "outgoing frame has no string op");
  const std::string& op = frame["op"].get_ref<const std::string&>();
  if (op == "status") {
    check(is_string_field(frame, "level") && is_string_field(frame, "msg"), "status without level or msg");
    // Cut to the hub's bound, where each invalid UTF-8 byte it kept is written as the 3-byte U+FFFD.
    check(frame["msg"].get_ref<const std::string&>().size() <= 3 * RosbridgeHub::kMaxStatusBytes,
          "status text not bounded");
  } else if (op == "publish") {
    check(is_string_field(frame, "topic") && frame.contains("msg"), "publish without topic or msg");
    check(frame["topic"].get_ref<const std::string&>().rfind("/lab/", 0) == 0, "publish outside the namespace");
  } else if (op == "service_response") {
    check(is_string_field(frame, "service"), "service_response without its service");
    check(frame.contains("result") && frame["result"].is_boolean(), "service_response without a boolean result");
    check(frame.contains("values"), "service_response without values");
    check(frame["result"].get<bool>() == frame["values"].is_object(), "service_response values disagree with its result");
  } else {
    check(false, "outgoing frame with an unknown op");
  }
  if (frame.contains("id")) {
    check(frame["id"].is_string() || frame["id"].is_number_integer(), "echoed id is neither string nor integer");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  RosbridgeHub hub("/lab");
  declare_topics(hub);
  const int connection = hub.open_connection({});
  RosbridgeSession session(hub, connection);

  session.on_text(rfbsim::fuzz::as_text(data, size));
  const std::deque<Frame> answers = hub.take_outgoing(connection, SIZE_MAX);
  check(answers.size() <= 3, "one op answered with more than three frames");
  for (const Frame& frame : answers) check_frame(*frame);

  // What the op subscribed to, if anything, now hears the simulation.
  hub.publish("/clock", {{"clock", {{"sec", 1}, {"nanosec", 5}}}});
  hub.publish("/scan", {{"ranges", {1.0, 2.0}}});
  hub.flush_due();
  session.on_text(R"({"op":"call_service","id":1,"service":"/rosapi/get_time"})");
  std::size_t frames = 0;
  for (const Frame& frame : hub.take_outgoing(connection, SIZE_MAX)) {
    check_frame(*frame);
    ++frames;
  }
  check(frames >= 1, "get_time after the input went unanswered");
  check(hub.last_clock().sec == 1 && hub.last_clock().nanosec == 5, "the hub lost /clock's time");

  for (const IncomingMessage& message : hub.take_incoming()) {
    const auto accepted = hub.accepted(message.topic);
    check(accepted.has_value(), "a message reached the simulation on a topic it does not take");
    check(message.msg.is_object(), "a message that is not a JSON object reached the simulation");
    bool type_ok = message.type.empty();
    for (const std::string& type : accepted->types) type_ok = type_ok || type == message.type;
    check(type_ok, "a message of a type the topic does not take reached the simulation");
    check(message.connection == connection, "a message names another connection");
  }
  hub.close_connection(connection);
  return 0;
}
