// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeServer: rosbridge v2 (JSON over WebSocket) served from a hub, the protocol ROS tools speak to a
// rosbridge_server (roslibjs, Foxglove, Lichtblick). The WebSocket is at "/"; each connection is a
// RosbridgeSession; the server only moves bytes, on one thread of its own (websocketpp on asio).
//
// This header names no websocketpp, Boost or OpenSSL type: websocketpp 0.8.2 only compiles as C++17 with
// g++ 12, so the implementation lives in a C++17 library and C++20 code includes this freely.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "ros/bridge/rosbridge_hub.hpp"

namespace rfbsim::ros {

/// Where and how the server listens; every field but port has a safe default.
struct RosbridgeServerOptions {
  /// Address to listen on. Loopback by default: anyone who reaches the port can drive the robot.
  std::string bind = "127.0.0.1";
  /// TCP port; 0 takes any free one (tests), port() says which.
  int port = 0;
  /// Largest inbound message, bytes; a larger one gets an error status and a close with 1009.
  std::size_t max_message_bytes = std::size_t{1} << 20;
  /// Connections at once; more are refused with HTTP 503. Accepted sockets, handshake or not, are capped
  /// at 4 times this; more are closed at once.
  int max_connections = 8;
  /// Outbound bytes queued per connection at most; a slow client loses its oldest messages.
  std::size_t max_queued_bytes_per_connection = std::size_t{8} << 20;
};

/// What the server has done, for tests and metrics.
struct RosbridgeServerStats {
  std::size_t open = 0;            ///< connections open now
  std::size_t opened = 0;          ///< connections whose handshake succeeded, ever
  std::size_t refused = 0;         ///< handshakes refused (wrong path, too many connections)
  std::size_t closed_oversized = 0;  ///< connections closed for an oversized message
  std::size_t sockets_refused = 0;   ///< TCP connections closed at accept, beyond 4 x max_connections sockets
};

class RosbridgeServer {
 public:
  /// Listens and starts the server's thread. Throws std::runtime_error naming the address when it cannot
  /// listen, std::invalid_argument for bad options. `hub` must outlive the server.
  RosbridgeServer(RosbridgeHub& hub, RosbridgeServerOptions options);
  /// Sends each connection what the hub still holds for it, closes it (1001), waits up to 1 s for that,
  /// stops the thread and forgets the hub connections.
  ~RosbridgeServer();
  RosbridgeServer(const RosbridgeServer&) = delete;
  RosbridgeServer& operator=(const RosbridgeServer&) = delete;

  /// The port listened on (the chosen one when options.port was 0).
  [[nodiscard]] int port() const;
  /// Counters; any thread.
  [[nodiscard]] RosbridgeServerStats stats() const;

  struct Impl;  // public only so that the implementation's templates can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::ros
