// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeLink: the ops a rosbridge client sends (ROSBRIDGE_PROTOCOL.md "Advertise", "Subscribe"; "latch"
// is rosbridge_library's advertise option for a latched, in ROS 2 transient-local, publisher) and what a
// server sends back (publish, status, call_service).
#include "ros/bridge/rosbridge_link.hpp"

#include "ros/bridge/op_parse.hpp"

namespace rfbsim::ros {

std::vector<std::string> RosbridgeLink::greeting() const {
  std::vector<std::string> ops;
  for (const DeclaredTopic& topic : hub_.declared_topics()) {
    nlohmann::json op = {{"op", "advertise"}, {"id", "rfbsim_advertise:" + topic.topic},
                         {"topic", hub_.wire_topic(topic.topic)}, {"type", short_ros_type(topic.type)}};
    if (topic.latched) op["latch"] = true;
    ops.push_back(op.dump());
  }
  for (const AcceptedTopic& topic : hub_.accepted_topics()) {
    const nlohmann::json op = {{"op", "subscribe"}, {"id", "rfbsim_subscribe:" + topic.topic},
                               {"topic", hub_.wire_topic(topic.topic)},
                               {"type", short_ros_type(topic.types.front())}};
    ops.push_back(op.dump());
  }
  return ops;
}

void RosbridgeLink::on_text(int connection, std::string_view text) {
  const ParsedOp parsed = parse_op(text);
  if (!parsed.error.empty()) return log_("server sent a frame we cannot read: " + parsed.error);
  const nlohmann::json& op = parsed.message;
  const std::string& name = op["op"].get_ref<const std::string&>();

  if (name == "publish") {
    const auto topic = op.find("topic");
    const auto msg = op.find("msg");
    if (topic == op.end() || !topic->is_string() || msg == op.end() || !msg->is_object()) {
      return log_("server sent a publish without a string \"topic\" and an object \"msg\"");
    }
    const std::optional<std::string> local = hub_.local_topic(topic->get<std::string>());
    const std::optional<AcceptedTopic> accepted = local ? hub_.accepted(*local) : std::nullopt;
    if (!accepted) return log_("server published on " + topic->get<std::string>() + ", which we did not subscribe to");
    // The subscription named the first type, so that is what rosbridge_server converts to.
    hub_.push_incoming(IncomingMessage{*local, accepted->types.front(), *msg, connection}, text.size());
  } else if (name == "status") {
    const auto string_or_empty = [&](const char* key) {
      const auto field = op.find(key);
      return field != op.end() && field->is_string() ? field->get<std::string>() : std::string();
    };
    const std::string level = string_or_empty("level");
    const std::string message = string_or_empty("msg");
    if (level == "error" || level == "warning") log_("server " + level + ": " + message);
  } else if (name == "call_service") {
    // We advertise no services; answer anyway so that the caller does not wait for a timeout.
    nlohmann::json response = {{"op", "service_response"}, {"result", false},
                               {"values", "rfbsim offers no ROS services"}};
    if (op.contains("service")) response["service"] = op["service"];
    if (const nlohmann::json id = op_id(op); !id.is_null()) response["id"] = id;
    hub_.send(connection, response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  // Anything else (service_response, set_level, ...) is not for us; drop it quietly.
}

}  // namespace rfbsim::ros
