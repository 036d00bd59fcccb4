// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's ROS side from its command line.
#include "app/ros_setup.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "rfbsim/log.hpp"

namespace rfbsim::sim {

std::string read_token_file(const std::string& path) {
  constexpr std::size_t kMaxToken = 4096;
  const std::string what = "--rosbridge-token-file " + path + ": ";
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::is_regular_file(status)) throw std::runtime_error(what + "not a readable file");
  // It authenticates this study's robot to the lab's ROS.
  using std::filesystem::perms;
  if ((status.permissions() & (perms::group_read | perms::others_read)) != perms::none) {
    rfbsim::log::warn("ros", "warning: %s can be read by other users; chmod 600 it", path.c_str());
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error(what + std::strerror(errno));
  // Read a little more than the longest token (and its line end), never the whole of a huge file.
  std::string head(kMaxToken + 3, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  std::string token = head.substr(0, head.find('\n'));
  if (!token.empty() && token.back() == '\r') token.pop_back();
  if (token.size() > kMaxToken) throw std::runtime_error(what + "the token is longer than 4096 characters");
  const bool printable = std::all_of(token.begin(), token.end(), [](unsigned char c) { return c > 0x20 && c < 0x7f; });
  if (token.empty() || !printable) {
    throw std::runtime_error(what + "the first line must hold the token (printable, no spaces)");
  }
  return token;
}

namespace {

// The bag's floor (ros::McapOptions::min_free_bytes): below it the bag would only take the space the session's
// own files need, so none is started.
constexpr std::uint64_t kBagMinFreeBytes = 64u << 20;

// Whether the file system holding `dir` has room for a bag beside the session's own files.
bool room_for_bag(const std::filesystem::path& dir) {
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(dir, ec);
  if (ec || space.available >= kBagMinFreeBytes) return true;  // unknown: the writer thread checks each chunk
  rfbsim::log::info("ros",
                    "%s has %ju KiB free, under the bag's 64 MiB floor: no session.mcap; the session's "
                    "other files keep the space",
                    dir.c_str(), static_cast<std::uintmax_t>(space.available >> 10));
  return false;
}

}  // namespace

std::unique_ptr<RosLink> open_ros_link(const SimOptions& options) {
  bool bag = !options.data_dir.empty() && options.mcap;
  if (!bag && !options.rosbridge_port && options.rosbridge_connect.empty()) return nullptr;
  RosLinkOptions ros;
  if (bag) {
    // SessionWriter refuses a folder that holds a session; refuse it here first, before a bag lands in it.
    if (std::filesystem::exists(std::filesystem::path(options.data_dir) / "session.json")) {
      throw std::runtime_error(options.data_dir + " already holds a session (session.json); give a new folder");
    }
    std::filesystem::create_directories(options.data_dir);
    bag = room_for_bag(options.data_dir);
    if (bag) ros.bag_file = std::filesystem::path(options.data_dir) / "session.mcap";
  }
  if (!bag && !options.rosbridge_port && options.rosbridge_connect.empty()) return nullptr;
  ros.server_port = options.rosbridge_port;
  ros.server_bind = options.rosbridge_bind;
  ros.connect_url = options.rosbridge_connect;
  if (!options.rosbridge_token_file.empty()) ros.token = read_token_file(options.rosbridge_token_file);
  ros.ca_file = options.rosbridge_ca;
  ros.topic_namespace = options.ros_namespace;
  ros.cmd_vel_type = options.cmd_vel_type;
  ros.tick_hz = options.tick_hz;
  auto link = std::make_unique<RosLink>(std::move(ros));
  if (const auto port = link->server_port()) {
    rfbsim::log::info("ros", "rosbridge v2 server on ws://%s:%d/ (unauthenticated: keep it on loopback)",
                      url_host(options.rosbridge_bind).c_str(), *port);
  }
  if (!options.rosbridge_connect.empty()) {
    rfbsim::log::info("ros", "rosbridge client dialling %s", options.rosbridge_connect.c_str());
  }
  return link;
}

}  // namespace rfbsim::sim
