// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's ROS side built from its command line (docs/ros.md): the bag's file, the rosbridge server and the
// dial-out with its token, and a word in the log about each.
#pragma once

#include <memory>
#include <string>

#include "app/options.hpp"
#include "app/ros_link.hpp"

namespace rfbsim::sim {

/// The dial-out's token: the first line of the file at `path`, at most 4096 printable characters without spaces
/// (sim_manager's bound too). Throws std::runtime_error naming the file when it cannot be read, is empty, or holds
/// more or other than that, never cutting a token short; warns when others may read the file.
std::string read_token_file(const std::string& path);

/// The RosLink the options ask for (a bag with --data-dir unless --no-mcap, a rosbridge server, a dial-out), or
/// null when they ask for none. Makes the data folder for the bag; refuses one that already holds a session.
/// Throws std::runtime_error naming what failed.
std::unique_ptr<RosLink> open_ros_link(const SimOptions& options);

}  // namespace rfbsim::sim
