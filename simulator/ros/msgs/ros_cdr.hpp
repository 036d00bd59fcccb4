// SPDX-License-Identifier: GPL-2.0-or-later
// ROS 2 messages in CDR (the bytes rosbag2 stores and a DDS subscriber receives): every field in the order of
// its .msg file, nested messages inline, sequences as a length and their elements, fixed arrays (float64[36])
// as their elements alone. The byte layout itself is ros/mcap/cdr_writer.hpp's.
#pragma once

#include <cstdint>
#include <vector>

#include "ros/msgs/ros_types.hpp"

namespace rfbsim::ros {

/// The message in CDR, with the 4-byte encapsulation header. Throws std::length_error for a string or
/// sequence longer than CDR can count (4 GiB).
std::vector<std::uint8_t> to_cdr(const RosPayload& payload);

/// Per-type forms of to_cdr.
std::vector<std::uint8_t> to_cdr(const Clock& message);
std::vector<std::uint8_t> to_cdr(const TFMessage& message);
std::vector<std::uint8_t> to_cdr(const Odometry& message);
std::vector<std::uint8_t> to_cdr(const LaserScan& message);
std::vector<std::uint8_t> to_cdr(const OccupancyGrid& message);
std::vector<std::uint8_t> to_cdr(const Twist& message);
std::vector<std::uint8_t> to_cdr(const TwistStamped& message);
std::vector<std::uint8_t> to_cdr(const People& message);
std::vector<std::uint8_t> to_cdr(const Path& message);
std::vector<std::uint8_t> to_cdr(const MarkerArray& message);
std::vector<std::uint8_t> to_cdr(const String& message);
std::vector<std::uint8_t> to_cdr(const PoseStamped& message);

}  // namespace rfbsim::ros
