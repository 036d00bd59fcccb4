// SPDX-License-Identifier: GPL-2.0-or-later
// call_rosapi: the rosapi services a rosbridge server's clients use to discover what it serves (Foxglove's
// and Lichtblick's Rosbridge connection, roslibjs's Ros.getTopics()), answered from a RosbridgeHub's declared
// and accepted topics. Pure: RosbridgeSession wraps the answer in a service_response. The service names are
// rosapi's own ("/rosapi/topics"), never under the hub's namespace: under sim_manager a lab's own
// rosbridge_server owns rosapi, and this is only our server's discovery (docs/ros.md).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "ros/bridge/rosbridge_hub.hpp"

namespace rfbsim::ros {

/// What a rosapi call answers: rosbridge's service_response "result" and "values".
struct RosapiAnswer {
  bool result = false;    ///< true: `values` holds the service's response fields
  nlohmann::json values;  ///< the response fields (an object), or a message saying why when result is false
};

/// The ROS node the simulation appears as in rosapi's nodes, publishers and subscribers.
inline constexpr const char* kRosapiNodeName = "/rfbsim";

/// Answers rosapi `service` called with `args` (the call_service op's "args": absent/null, an object, or
/// rosbridge's positional list) from `hub`; nullopt when `service` is not one of rosapi_services().
std::optional<RosapiAnswer> call_rosapi(const RosbridgeHub& hub, std::string_view service,
                                        const nlohmann::json& args);

/// The rosapi services call_rosapi answers, sorted by name.
const std::vector<std::string>& rosapi_services();

}  // namespace rfbsim::ros
