// SPDX-License-Identifier: GPL-2.0-or-later
// ros2msg_typedefs: a full ros2msg definition (the text ros::ros2msg_schema writes and rosapi's topics_and_raw_types
// hands out) turned into rosapi's TypeDef list, the answer of rosapi's message_details service (roslibjs's
// Ros.getMessageDetails, decoded by its decodeTypeDefs). Pure, C++17 clean.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

namespace rfbsim::ros {

/// One TypeDef per message type in `definition` ("pkg/msg/Type" or "pkg/Type" `type`'s own fields, then each nested
/// type after a line of '=' and "MSG: pkg/Type"), `type` first. Each is an object with rosapi_msgs' TypeDef fields:
/// type, fieldnames, fieldtypes, fieldarraylen (-1: not an array, 0: unbounded or bounded, N: fixed), examples,
/// constnames, constvalues. Nested message types are written pkg/msg/Type everywhere, so that a field's type names
/// its TypeDef; primitives keep their name ("float64", "string"). An empty array for an empty definition or a
/// malformed `type`.
nlohmann::json ros2msg_typedefs(std::string_view type, std::string_view definition);

}  // namespace rfbsim::ros
