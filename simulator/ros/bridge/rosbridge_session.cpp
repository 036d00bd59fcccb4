// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeSession: each op's fields checked against rosbridge_suite's ROSBRIDGE_PROTOCOL.md (sections
// "Advertise", "Publish", "Subscribe", "Unsubscribe", "Call Service", "Set Status Level", "Status message"),
// then handed to the hub. Every refusal names the op, the field and what was expected.
#include "ros/bridge/rosbridge_session.hpp"

#include <climits>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "ros/bridge/op_parse.hpp"
#include "ros/bridge/ros_names.hpp"
#include "ros/bridge/rosapi_services.hpp"

namespace rfbsim::ros {

namespace {

// Ops of the protocol that rfbsim does not offer: a clear "not supported" rather than "unknown".
bool is_unsupported_op(const std::string& op) {
  for (const char* name : {"fragment", "png", "advertise_service", "unadvertise_service", "service_response",
                           "advertise_action", "unadvertise_action", "cancel_action_goal",
                           "action_feedback", "action_result"}) {
    if (op == name) return true;
  }
  return false;
}

// A required string field; nullptr when absent or not a string.
const std::string* string_field(const nlohmann::json& op, const char* name) {
  const auto field = op.find(name);
  if (field == op.end() || !field->is_string()) return nullptr;
  return field->get_ptr<const std::string*>();
}

// An optional non-negative integer field (an integral float such as 100.0 counts): nullopt when absent,
// -1 when present but not a non-negative integer within int.
std::optional<int> count_field(const nlohmann::json& op, const char* name) {
  const auto field = op.find(name);
  if (field == op.end() || field->is_null()) return std::nullopt;
  if (field->is_number_unsigned() && field->get<std::uint64_t>() <= static_cast<std::uint64_t>(INT_MAX)) {
    return static_cast<int>(field->get<std::uint64_t>());
  }
  if (field->is_number_integer()) {
    const std::int64_t value = field->get<std::int64_t>();
    return value >= 0 && value <= INT_MAX ? static_cast<int>(value) : -1;
  }
  if (field->is_number_float()) {
    const double value = field->get<double>();
    if (value >= 0 && value <= INT_MAX && std::floor(value) == value) return static_cast<int>(value);
  }
  return -1;
}

std::string join(const std::vector<std::string>& items) {
  std::string joined;
  for (const std::string& item : items) joined += (joined.empty() ? "" : ", ") + item;
  return joined;
}

bool contains(const std::vector<std::string>& items, const std::string& item) {
  for (const std::string& candidate : items) {
    if (candidate == item) return true;
  }
  return false;
}

// action_msgs/msg/GoalStatus STATUS_ABORTED.
constexpr int kGoalStatusAborted = 6;

std::string id_text(const nlohmann::json& id) {
  if (id.is_string()) return id.get<std::string>();
  return id.is_null() ? "" : id.dump();
}

}  // namespace

void RosbridgeSession::on_text(std::string_view text) {
  text_bytes_ = text.size();
  ParsedOp parsed = parse_op(text);
  const nlohmann::json id = op_id(parsed.message);
  if (!parsed.error.empty()) {
    error(parsed.error, id);
    return;
  }
  nlohmann::json& op = parsed.message;
  if (op.contains("id") && id.is_null()) {
    error("\"id\" must be a string or an integer", nullptr);
    return;
  }
  const std::string& name = op["op"].get_ref<const std::string&>();
  if (name == "advertise") {
    advertise(op, id);
  } else if (name == "unadvertise") {
    unadvertise(op, id);
  } else if (name == "publish") {
    publish(op, id);
  } else if (name == "subscribe") {
    subscribe(op, id);
  } else if (name == "unsubscribe") {
    unsubscribe(op, id);
  } else if (name == "call_service") {
    call_service(op, id);
  } else if (name == "send_action_goal") {
    send_action_goal(op, id);
  } else if (name == "set_level") {
    set_level(op, id);
  } else if (name == "status") {
    // A client's own status report: nothing to do.
  } else if (is_unsupported_op(name)) {
    error("op '" + name + "' is not supported by rfbsim", id);
  } else {
    error("unknown op '" + name + "'", id);
  }
}

void RosbridgeSession::on_binary() {
  error("binary frames (CBOR) are not supported: send JSON text frames", nullptr);
}

std::optional<std::string> RosbridgeSession::oversized_status(std::size_t bytes, std::size_t max_bytes) const {
  return hub_.status_frame(connection_, StatusLevel::kError,
                           "message of " + std::to_string(bytes) + " bytes is over the limit of " +
                               std::to_string(max_bytes) + " bytes; closing",
                           nullptr);
}

void RosbridgeSession::advertise(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* topic = string_field(op, "topic");
  const std::string* type = string_field(op, "type");
  if (topic == nullptr || type == nullptr) return error("advertise needs string \"topic\" and \"type\"", id);
  const std::optional<std::string> local = hub_.local_topic(*topic);
  if (!local) return error("advertise: no such topic '" + *topic + "'", id);
  if (hub_.declared(*local)) return error("advertise: " + *topic + " is published by the simulator only", id);
  const std::optional<AcceptedTopic> accepted = hub_.accepted(*local);
  if (!accepted) return error("advertise: the simulator takes nothing on " + *topic, id);
  const std::string normalized = normalize_ros_type(*type);
  if (normalized.empty()) return error("advertise: malformed type '" + *type + "'", id);
  if (!contains(accepted->types, normalized)) {
    return error("advertise: " + *topic + " takes " + join(accepted->types) + ", not " + *type, id);
  }
  advertised_[*local] = normalized;
  hub_.send_status(connection_, StatusLevel::kInfo, "advertised " + *topic, id);
}

void RosbridgeSession::unadvertise(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* topic = string_field(op, "topic");
  if (topic == nullptr) return error("unadvertise needs a string \"topic\"", id);
  const std::optional<std::string> local = hub_.local_topic(*topic);
  if (!local || advertised_.erase(*local) == 0) {
    hub_.send_status(connection_, StatusLevel::kWarning, "unadvertise: " + *topic + " was not advertised", id);
  }
}

void RosbridgeSession::publish(nlohmann::json& op, const nlohmann::json& id) {
  const std::string* topic = string_field(op, "topic");
  if (topic == nullptr) return error("publish needs a string \"topic\"", id);
  const auto msg = op.find("msg");
  if (msg == op.end() || !msg->is_object()) return error("publish: \"msg\" must be a JSON object", id);
  const std::optional<std::string> local = hub_.local_topic(*topic);
  if (!local) return error("publish: no such topic '" + *topic + "'", id);
  if (hub_.declared(*local)) return error("publish: " + *topic + " is published by the simulator only", id);
  const std::optional<AcceptedTopic> accepted = hub_.accepted(*local);
  if (!accepted) return error("publish: the simulator takes nothing on " + *topic, id);

  // The type: a "type" key on the publish (roslibjs and others send one), else the advertised one, else the
  // topic's only accepted type. A null "type" counts as absent, as on subscribe.
  std::string type;
  if (op.contains("type") && !op["type"].is_null()) {
    const std::string* named = string_field(op, "type");
    type = named == nullptr ? "" : normalize_ros_type(*named);
    if (type.empty()) return error("publish: malformed \"type\"", id);
  } else if (const auto advertised = advertised_.find(*local); advertised != advertised_.end()) {
    type = advertised->second;
  } else if (accepted->types.size() == 1) {
    type = accepted->types.front();
  }
  if (!type.empty() && !contains(accepted->types, type)) {
    return error("publish: " + *topic + " takes " + join(accepted->types) + ", not " + type, id);
  }
  // Moved, not copied: the frame's parse is dropped right after, and a copy would double its memory.
  hub_.push_incoming(IncomingMessage{*local, type, std::move(*msg), connection_}, text_bytes_);
}

void RosbridgeSession::subscribe(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* topic = string_field(op, "topic");
  if (topic == nullptr) return error("subscribe needs a string \"topic\"", id);
  const std::optional<std::string> local = hub_.local_topic(*topic);
  if (!local) return error("subscribe: no such topic '" + *topic + "'", id);
  const std::optional<DeclaredTopic> declared = hub_.declared(*local);
  if (!declared) {
    if (hub_.accepted(*local)) return error("subscribe: " + *topic + " is published by clients, not the simulator", id);
    return error("subscribe: no such topic '" + *topic + "'", id);
  }
  if (op.contains("type") && !op["type"].is_null()) {
    const std::string* type = string_field(op, "type");
    if (type == nullptr) return error("subscribe: \"type\" must be a string", id);
    const std::string normalized = normalize_ros_type(*type);
    if (normalized.empty()) return error("subscribe: malformed type '" + *type + "'", id);
    if (normalized != declared->type) {
      return error("subscribe: " + *topic + " is " + declared->type + ", not " + *type, id);
    }
  }
  const std::optional<int> throttle = count_field(op, "throttle_rate");
  const std::optional<int> queue_length = count_field(op, "queue_length");
  const std::optional<int> fragment_size = count_field(op, "fragment_size");
  if (throttle == -1) return error("subscribe: \"throttle_rate\" must be a non-negative integer (ms)", id);
  if (queue_length == -1) return error("subscribe: \"queue_length\" must be a non-negative integer", id);
  if (fragment_size == -1) return error("subscribe: \"fragment_size\" must be a non-negative integer", id);
  if (op.contains("compression") && !op["compression"].is_null()) {
    const std::string* compression = string_field(op, "compression");
    if (compression == nullptr) return error("subscribe: \"compression\" must be a string", id);
    if (*compression != "none") {
      hub_.send_status(connection_, StatusLevel::kWarning,
                       "subscribe: compression '" + *compression + "' is not supported; sending plain JSON", id);
    }
  }
  const SubscribeOptions options{id_text(id), throttle.value_or(0), queue_length.value_or(0)};
  const std::string refused = hub_.subscribe(connection_, *local, options);
  if (!refused.empty()) return error("subscribe: " + *topic + " refused: " + refused, id);
  // Subscribed, with the hub's cut of the queue: said, so that a client does not count on the longer one.
  if (options.queue_length > RosbridgeHub::kMaxQueueLength) {
    hub_.send_status(connection_, StatusLevel::kWarning,
                     "subscribe: queue_length " + std::to_string(options.queue_length) + " is over the limit; " +
                         std::to_string(RosbridgeHub::kMaxQueueLength) + " is used",
                     id);
  }
  hub_.send_status(connection_, StatusLevel::kInfo, "subscribed to " + *topic, id);
}

void RosbridgeSession::unsubscribe(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* topic = string_field(op, "topic");
  if (topic == nullptr) return error("unsubscribe needs a string \"topic\"", id);
  const std::optional<std::string> local = hub_.local_topic(*topic);
  if (!local || !hub_.unsubscribe(connection_, *local, id_text(id))) {
    hub_.send_status(connection_, StatusLevel::kWarning, "unsubscribe: not subscribed to " + *topic, id);
  }
}

void RosbridgeSession::call_service(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* service = string_field(op, "service");
  if (service == nullptr) return error("call_service needs a string \"service\"", id);
  const auto args = op.find("args");
  // The one place a service name is made absolute: roslibjs's Ros helpers call "rosapi/topics", other clients
  // "/rosapi/topics", and both mean the same service.
  const std::optional<std::string> name = normalize_service(*service);
  std::optional<RosapiAnswer> answer;
  if (name) answer = call_rosapi(hub_, *name, args == op.end() ? nlohmann::json() : *args);
  // Any other service: a failed response rather than silence, so that the caller does not wait.
  if (!answer) answer = RosapiAnswer{false, "rfbsim offers no service '" + *service + "', only rosapi's discovery"};
  // "service" echoes the name as the client wrote it, as rosbridge_server does.
  nlohmann::json response = {{"op", "service_response"}, {"service", *service}, {"result", answer->result},
                             {"values", std::move(answer->values)}};
  if (!id.is_null()) response["id"] = id;
  hub_.send(connection_, response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

void RosbridgeSession::send_action_goal(const nlohmann::json& op, const nlohmann::json& id) {
  // A failed action_result, which roslibjs's Action.sendGoal hands to its failed callback at once (a status
  // message it never surfaces, and the caller would wait forever). status 6 is action_msgs/GoalStatus's
  // STATUS_ABORTED: the goal ends without running.
  const std::string* action = string_field(op, "action");
  const std::string why = "rfbsim offers no actions" + (action == nullptr ? "" : ", not '" + *action + "'");
  nlohmann::json result = {{"op", "action_result"},
                           {"action", action == nullptr ? nlohmann::json() : nlohmann::json(*action)},
                           {"values", why},
                           {"status", kGoalStatusAborted},
                           {"result", false}};
  if (!id.is_null()) result["id"] = id;
  hub_.send(connection_, result.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

void RosbridgeSession::set_level(const nlohmann::json& op, const nlohmann::json& id) {
  const std::string* level = string_field(op, "level");
  const std::optional<StatusLevel> parsed = level == nullptr ? std::nullopt : parse_status_level(*level);
  if (!parsed) return error("set_level: \"level\" must be one of info, warning, error, none", id);
  hub_.set_level(connection_, *parsed);
}

void RosbridgeSession::error(const std::string& text, const nlohmann::json& id) {
  hub_.send_status(connection_, StatusLevel::kError, text, id);
}

}  // namespace rfbsim::ros
