// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeSession: the rosbridge v2 server side of one client connection, as pure protocol: it reads the
// client's ops (advertise, unadvertise, publish, subscribe, unsubscribe, call_service, set_level) and turns
// them into hub subscriptions, incoming messages and replies queued on the hub; call_service answers rosapi's
// discovery services (ros/bridge/rosapi_services.hpp), with or without the leading slash, and any other service
// with a failed service_response; send_action_goal gets a failed action_result, as client libraries (roslibjs's
// Action.sendGoal) surface only those. It never touches a socket:
// RosbridgeServer moves its bytes. Bad input of any kind gets an error status and the connection stays open.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "ros/bridge/rosbridge_hub.hpp"

namespace rfbsim::ros {

class RosbridgeSession {
 public:
  /// Serves hub connection `connection` of `hub` (both outlive the session).
  RosbridgeSession(RosbridgeHub& hub, int connection) : hub_(hub), connection_(connection) {}

  /// Handles one text frame.
  void on_text(std::string_view text);
  /// Handles one binary frame: rosbridge's CBOR, which we do not speak (an error status).
  void on_binary();
  /// The error status for a frame of `bytes` over `max_bytes`, serialized and not queued: the server sends
  /// it straight ahead of its 1009 close, past whatever backlog waits. nullopt when the client muted errors.
  [[nodiscard]] std::optional<std::string> oversized_status(std::size_t bytes, std::size_t max_bytes) const;

 private:
  void advertise(const nlohmann::json& op, const nlohmann::json& id);
  void unadvertise(const nlohmann::json& op, const nlohmann::json& id);
  void publish(nlohmann::json& op, const nlohmann::json& id);  // takes op's "msg"
  void subscribe(const nlohmann::json& op, const nlohmann::json& id);
  void unsubscribe(const nlohmann::json& op, const nlohmann::json& id);
  void call_service(const nlohmann::json& op, const nlohmann::json& id);
  void send_action_goal(const nlohmann::json& op, const nlohmann::json& id);  // a failed action_result
  void set_level(const nlohmann::json& op, const nlohmann::json& id);
  void error(const std::string& text, const nlohmann::json& id);

  RosbridgeHub& hub_;
  const int connection_;
  std::map<std::string, std::string> advertised_;  // simulation topic -> normalized type this client named
  std::size_t text_bytes_ = 0;                     // the size of the frame being handled
};

}  // namespace rfbsim::ros
