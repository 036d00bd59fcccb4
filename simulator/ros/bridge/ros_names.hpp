// SPDX-License-Identifier: GPL-2.0-or-later
// ROS names as rosbridge carries them: message type names in both spellings ROS users write
// ("geometry_msgs/Twist" from ROS 1 and roslibjs, "geometry_msgs/msg/Twist" from ROS 2), topic names, and the
// namespace a hub puts in front of every topic on the wire. Pure functions, C++17 and C++20 clean.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace rfbsim::ros {

/// "geometry_msgs/Twist" -> "geometry_msgs/msg/Twist"; "pkg/msg/Type" is kept; "" when malformed (not two or
/// three '/'-separated parts, a middle part other than "msg", or a part that is not a ROS identifier).
std::string normalize_ros_type(std::string_view type);

/// "geometry_msgs/msg/Twist" -> "geometry_msgs/Twist": the spelling both ROS 1's and ROS 2's rosbridge_server
/// resolve, used on the dial-out link; "" when `type` is malformed.
std::string short_ros_type(std::string_view type);

/// A topic name made absolute: "cmd_vel" -> "/cmd_vel", "/a//b/" -> nullopt. Valid names are '/'-separated
/// ROS identifiers (letters, digits, '_'; not starting with a digit); nullopt when malformed.
std::optional<std::string> normalize_topic(std::string_view topic);

/// A service name made absolute, by the same rules as topics: "rosapi/topics" (as roslibjs's Ros helpers write
/// it) -> "/rosapi/topics"; nullopt when malformed.
std::optional<std::string> normalize_service(std::string_view service);

/// A topic namespace as given to RosbridgeHub: "" stays "", "/rfbsim/s1/" -> "/rfbsim/s1"; nullopt when it is
/// not "" and not a valid absolute topic name.
std::optional<std::string> normalize_namespace(std::string_view ns);

}  // namespace rfbsim::ros
