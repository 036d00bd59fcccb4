// SPDX-License-Identifier: GPL-2.0-or-later
// ros2msg schemas: the message definitions an MCAP file in the ros2 profile stores with each channel, so that
// readers without ROS installed (Foxglove, Lichtblick, the npm and Python readers) can decode the CDR.
#pragma once

#include <string>
#include <string_view>

namespace rfbsim::ros {

/// The complete ros2msg definition of `type` ("pkg/msg/Type"; "pkg/Type" is accepted too), laid out as
/// rosbag2's MCAP storage writes it: the type's own .msg text, then each type it uses, once, depth first in
/// name order, after a line of 80 '=' and a line "MSG: pkg/Type". Comments are left out; constants stay.
/// Throws std::invalid_argument naming the type when it is not one of ros_types.hpp's.
std::string ros2msg_schema(std::string_view type);

}  // namespace rfbsim::ros
