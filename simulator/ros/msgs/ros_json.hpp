// SPDX-License-Identifier: GPL-2.0-or-later
// ROS 2 messages as rosbridge v2 carries them (the "msg" of a publish op): an object per message with the .msg's
// field names, Time and Duration as {"sec", "nanosec"}, numbers as numbers (int8[] as an array of numbers),
// and a float that is NaN or infinite as null, which is what rosbridge's JSON encoder writes for them.
// Also the one message rfbsim reads from rosbridge clients: a velocity command on /cmd_vel.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "ros/msgs/ros_types.hpp"

namespace rfbsim::ros {

/// The message in rosbridge's ROS 2 JSON form.
nlohmann::json to_json(const RosPayload& payload);
/// TwistStamped (not published, but what Jazzy stacks send on /cmd_vel) in the same form.
nlohmann::json to_json(const TwistStamped& message);

/// The velocity command in `msg` (a publish op's "msg"), of `type` "geometry_msgs/msg/Twist" or
/// "geometry_msgs/msg/TwistStamped" ("pkg/Type" spellings too), or "" to guess (a "twist" key means stamped).
/// A missing field reads as 0, as rosbridge fills in defaults. Returns none, with `error` saying what is wrong
/// in words, for another type, a field that is not in the message, a value of the wrong JSON type, or a
/// number that is not finite.
std::optional<Twist> twist_from_json(const nlohmann::json& msg, std::string_view type, std::string& error);

}  // namespace rfbsim::ros
