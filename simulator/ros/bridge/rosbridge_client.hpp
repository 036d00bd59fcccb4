// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeClient: dials out to a lab's rosbridge_server (ws:// or wss://, optionally with a bearer token),
// so that the lab's ROS 1 or ROS 2 stack drives the robot without opening a port on the study server. On
// each connection it advertises the hub's declared topics, subscribes to its accepted ones, then forwards
// every publish; the server's publishes become incoming messages. It reconnects with backoff, forever,
// on its own thread (websocketpp on asio), and never throws after construction.
//
// This header names no websocketpp, Boost or OpenSSL type (see rosbridge_server.hpp for why).
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "ros/bridge/rosbridge_hub.hpp"

namespace rfbsim::ros {

/// Where to dial and how.
struct RosbridgeClientOptions {
  /// ws://HOST[:PORT]/PATH or wss://...
  std::string url;
  /// Sent as "Authorization: Bearer <token>" on the opening handshake when not empty. Over ws:// anyone on
  /// the path can read it: use wss:// beyond a trusted network.
  std::string token;
  /// wss only: a PEM file of further trusted CA certificates, added to the system's. The peer's certificate
  /// is always verified and must name the URL's host.
  std::string ca_file;
  /// Longest wait between two connection attempts; waits start at 0.5 s and double up to this, and start
  /// over after a connection that stayed open 10 s. Each wait is spread by +-25 %.
  std::chrono::milliseconds max_backoff{30000};
  /// Outbound bytes queued at most while the server reads slowly; the oldest messages are dropped beyond.
  std::size_t max_queued_bytes = std::size_t{8} << 20;
  /// Largest message taken from the server, bytes; a larger one ends the connection (close 1009).
  std::size_t max_message_bytes = std::size_t{1} << 20;
  /// How often an open connection is pinged (WebSocket ping), so that a link that died silently is noticed.
  std::chrono::milliseconds keepalive_interval{5000};
  /// A connection that has sent nothing, pong or message, for this long is dropped and dialled again.
  std::chrono::milliseconds pong_timeout{10000};
};

class RosbridgeClient {
 public:
  /// Checks the options and starts dialling on the client's thread. Throws std::invalid_argument naming
  /// the URL when it is malformed, std::runtime_error when ca_file cannot be loaded. `hub` must outlive it.
  RosbridgeClient(RosbridgeHub& hub, RosbridgeClientOptions options);
  /// Sends what the hub still holds for the connection, closes it (1001), waits up to 1 s for that, stops
  /// the thread and forgets the hub connection.
  ~RosbridgeClient();
  RosbridgeClient(const RosbridgeClient&) = delete;
  RosbridgeClient& operator=(const RosbridgeClient&) = delete;

  /// True while a connection is open; any thread.
  [[nodiscard]] bool connected() const;
  /// Connections opened so far (reconnects included); any thread.
  [[nodiscard]] int connections_opened() const;
  /// Connection attempts that failed before opening (refused, TLS or HTTP refusal), ever; any thread.
  [[nodiscard]] int failed_attempts() const;

  struct Impl;  // public only so that the implementation's templates can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::ros
