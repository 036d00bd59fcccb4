// SPDX-License-Identifier: GPL-2.0-or-later
// call_rosapi: each answer has the fields of rosbridge_suite's rosapi_msgs service definitions
// (rosapi_msgs/srv/Topics.srv: topics, types; TopicsAndRawTypes.srv: topics, types, typedefs_full_text;
// GetROSVersion.srv: version, distro; GetTime.srv: time; Nodes.srv: nodes; Services.srv: services;
// TopicType.srv: topic -> type; Publishers.srv: topic -> publishers; Subscribers.srv: topic -> subscribers;
// MessageDetails.srv: type -> typedefs).
// As rosapi does, a topic nobody knows gets an empty answer (type "", no publishers), not a failure.
#include "ros/bridge/rosapi_services.hpp"

#include <algorithm>

#include "ros/bridge/ros2msg_typedefs.hpp"

namespace rfbsim::ros {

namespace {

using nlohmann::json;

// A topic as rosapi lists it: its wire name, one type, and who publishes or takes it.
struct ListedTopic {
  std::string wire;  // with the hub's namespace
  std::string type;  // pkg/msg/Type
  bool from_simulation = false;  // declared (the simulation publishes) rather than accepted (it subscribes)
};

// Declared topics first, then accepted ones with their preferred type: a ROS 2 graph lists a topic the
// simulation only subscribes to as well, and rosapi names one type per topic.
std::vector<ListedTopic> listed_topics(const RosbridgeHub& hub) {
  std::vector<ListedTopic> topics;
  for (const DeclaredTopic& topic : hub.declared_topics()) {
    topics.push_back({hub.wire_topic(topic.topic), topic.type, true});
  }
  for (const AcceptedTopic& topic : hub.accepted_topics()) {
    topics.push_back({hub.wire_topic(topic.topic), topic.types.front(), false});
  }
  return topics;
}

// The request's "topic": from an args object, or the first of rosbridge's positional args; nullopt when none.
std::optional<std::string> topic_arg(const json& args) {
  const json* topic = nullptr;
  if (args.is_object()) {
    const auto found = args.find("topic");
    if (found != args.end()) topic = &*found;
  } else if (args.is_array() && args.size() == 1) {
    topic = &args[0];
  }
  if (topic == nullptr || !topic->is_string()) return std::nullopt;
  return topic->get<std::string>();
}

// The listed topic whose wire name is `wire` (either way a client may write it: "scan" or "/scan").
std::optional<ListedTopic> find_topic(const RosbridgeHub& hub, const std::string& wire) {
  const std::optional<std::string> local = hub.local_topic(wire);
  if (!local) return std::nullopt;
  for (ListedTopic& topic : listed_topics(hub)) {
    if (topic.wire == hub.wire_topic(*local)) return std::move(topic);
  }
  return std::nullopt;
}

RosapiAnswer ok(json values) { return {true, std::move(values)}; }

// message_details: the TypeDefs of a type the simulation has a definition of (its topics' types), parsed from
// the same text topics_and_raw_types hands out. Unlike a topic, an unknown type fails: an empty list would
// leave roslibjs's decodeTypeDefs nothing to read.
RosapiAnswer message_details(const RosbridgeHub& hub, const json& args) {
  const json* type = nullptr;
  if (args.is_object() && args.contains("type")) type = &args["type"];
  if (args.is_array() && args.size() == 1) type = &args[0];
  if (type == nullptr || !type->is_string()) {
    return {false, "/rosapi/message_details needs a string \"type\" in \"args\""};
  }
  const std::string normalized = normalize_ros_type(type->get<std::string>());
  json typedefs = normalized.empty() ? json::array() : ros2msg_typedefs(normalized, hub.definition(normalized));
  if (typedefs.empty()) {
    return {false, "/rosapi/message_details: no definition of '" + type->get<std::string>() +
                       "'; rfbsim knows its topics' types (rosapi/topics_and_raw_types)"};
  }
  return ok({{"typedefs", std::move(typedefs)}});
}

RosapiAnswer topic_list(const RosbridgeHub& hub, bool with_definitions) {
  json names = json::array();
  json types = json::array();
  json definitions = json::array();
  for (const ListedTopic& topic : listed_topics(hub)) {
    names.push_back(topic.wire);
    types.push_back(topic.type);
    if (with_definitions) definitions.push_back(hub.definition(topic.type));
  }
  json values = {{"topics", std::move(names)}, {"types", std::move(types)}};
  if (with_definitions) values["typedefs_full_text"] = std::move(definitions);
  return ok(std::move(values));
}

// topic_type, publishers and subscribers: one topic in, one field out.
RosapiAnswer about_topic(const RosbridgeHub& hub, std::string_view service, const json& args) {
  const std::optional<std::string> wire = topic_arg(args);
  if (!wire) return {false, std::string(service) + " needs a string \"topic\" in \"args\""};
  const std::optional<ListedTopic> topic = find_topic(hub, *wire);
  const json us = json::array({kRosapiNodeName});
  if (service == "/rosapi/topic_type") return ok({{"type", topic ? topic->type : ""}});
  if (service == "/rosapi/publishers") {
    return ok({{"publishers", topic && topic->from_simulation ? us : json::array()}});
  }
  return ok({{"subscribers", topic && !topic->from_simulation ? us : json::array()}});
}

}  // namespace

const std::vector<std::string>& rosapi_services() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> sorted = {"/rosapi/get_ros_version", "/rosapi/get_time",
                                       "/rosapi/message_details", "/rosapi/nodes",
                                       "/rosapi/publishers",
                                       "/rosapi/services",        "/rosapi/subscribers",
                                       "/rosapi/topic_type",      "/rosapi/topics",
                                       "/rosapi/topics_and_raw_types"};
    std::sort(sorted.begin(), sorted.end());
    return sorted;
  }();
  return names;
}

std::optional<RosapiAnswer> call_rosapi(const RosbridgeHub& hub, std::string_view service, const json& args) {
  const std::vector<std::string>& names = rosapi_services();
  if (std::find(names.begin(), names.end(), service) == names.end()) return std::nullopt;
  // rosbridge's "args" is an object of the request's fields or a list of them in order; absent means none.
  if (!args.is_null() && !args.is_object() && !args.is_array()) {
    return RosapiAnswer{false, std::string(service) + ": \"args\" must be an object or a list"};
  }
  if (service == "/rosapi/topics") return topic_list(hub, false);
  if (service == "/rosapi/topics_and_raw_types") return topic_list(hub, true);
  // rfbsim speaks for ROS 2 Humble, the distribution its message definitions follow (docs/ros.md).
  if (service == "/rosapi/get_ros_version") return ok({{"version", 2}, {"distro", "humble"}});
  if (service == "/rosapi/get_time") {
    const RosTime time = hub.last_clock();
    return ok({{"time", {{"sec", time.sec}, {"nanosec", time.nanosec}}}});
  }
  if (service == "/rosapi/nodes") return ok({{"nodes", json::array({kRosapiNodeName})}});
  if (service == "/rosapi/services") return ok({{"services", names}});
  if (service == "/rosapi/message_details") return message_details(hub, args);
  return about_topic(hub, service, args);
}

}  // namespace rfbsim::ros
