// SPDX-License-Identifier: GPL-2.0-or-later
// RosLink: sim_rfb's ROS side (docs/ros.md). After every tick it samples the world into ROS messages
// (ros/msgs/ros_topics.hpp) and hands each to the session's bag (session.mcap: CDR, chunked, written on a
// thread of its own) and to rosbridge (JSON, only for topics someone subscribes to). It owns the rosbridge
// server (--rosbridge-port) and/or the dial-out client (--rosbridge-connect), and hands the velocity commands they
// received to the simulation thread. Nothing here blocks the simulation thread on the disk or the network.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_stack.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What sim_rfb's command line asks of ROS.
struct RosLinkOptions {
  std::filesystem::path bag_file;   ///< session.mcap to write; empty = no bag
  std::optional<int> server_port;   ///< rosbridge server port (0 = any free); none = no server
  std::string server_bind = "127.0.0.1";
  std::string connect_url;          ///< rosbridge server to dial out to; empty = none
  std::string token;                ///< Bearer token for the dial-out
  std::string ca_file;              ///< extra CAs for wss
  std::string topic_namespace;      ///< "" or "/rfbsim/s1"
  /// /cmd_vel's type for the dial-out's subscribe (the lab's rosbridge_server creates its subscriber with it).
  std::string cmd_vel_type = "geometry_msgs/msg/Twist";
  int tick_hz = 60;
};

/// A velocity command a rosbridge client sent on /cmd_vel.
struct RobotCommand {
  double v = 0.0;          ///< m/s
  double w = 0.0;          ///< rad/s
  std::string source;      ///< "rosbridge" (a client of our server) or "rosbridge-client" (the lab's server)
  int connection = 0;      ///< the hub's id of the connection that sent it (the dial-out has one too)
};

class RosLink {
 public:
  /// Opens the bag and starts the bridge. Throws std::runtime_error naming what failed (a bag that cannot be
  /// created, a port that cannot be bound, a bad URL).
  explicit RosLink(RosLinkOptions options);
  ~RosLink();
  RosLink(const RosLink&) = delete;
  RosLink& operator=(const RosLink&) = delete;

  /// The messages due at the world's tick now: call once before the first step and after every step.
  void sample(const World& world, const RobotStack* robot);
  /// A study event (an events.jsonl line) at `tick`, published on /events and written to the bag.
  void event(std::uint64_t tick, const std::string& json_line);
  /// The /cmd_vel commands received since the last call, in order. Malformed ones were answered with an
  /// error status to their sender and are not here.
  std::vector<RobotCommand> take_commands();
  /// Tells the sender of an ignored command why (a warning status, once per connection).
  void warn_ignored(const RobotCommand& command, const std::string& why);
  /// Closes the bag's open chunk when it is due (about once a second), so that a crash loses at most that.
  void flush_if_due();
  /// Writes the bag's summary and waits for it to be on disk; stops the bridge. Later calls do nothing.
  void finish();

  /// The rosbridge server's port (after binding port 0), or none without a server.
  [[nodiscard]] std::optional<int> server_port() const;
  /// Whether it writes a bag (session.mcap).
  [[nodiscard]] bool writes_bag() const;
  /// Why the bag stopped being written (a full disk), if it did.
  [[nodiscard]] std::optional<std::string> bag_failure() const;
  /// "server 127.0.0.1:9090" ("server [::1]:9090"), "client wss://...", "server ... + client ..." or "" (for
  /// session.json).
  [[nodiscard]] std::string bridge_description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A numeric address as a URL's host: an IPv6 one in brackets ("[::1]"), any other as it is.
std::string url_host(const std::string& address);

}  // namespace rfbsim::sim
