// SPDX-License-Identifier: GPL-2.0-or-later
// SourceForwarder: a loopback TCP port whose connections are passed on to another loopback port from a chosen
// source address (e.g. 127.0.0.5), so that tests can play a participant at an address other than 127.0.0.1
// with clients (the HTTP client, the WebSocket bridge) that cannot bind one themselves.
#pragma once

#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace rfbsim::test {

class SourceForwarder {
 public:
  /// Listens on 127.0.0.1 at an ephemeral port; each accepted connection is connected to 127.0.0.1:`target_port`
  /// from `source_address` (any 127.x.y.z works on Linux without set-up) and bytes are copied both ways until
  /// either side closes. Throws std::runtime_error when the listening socket cannot be set up.
  SourceForwarder(const std::string& source_address, int target_port);
  /// Closes every connection and joins the threads.
  ~SourceForwarder();
  SourceForwarder(const SourceForwarder&) = delete;
  SourceForwarder& operator=(const SourceForwarder&) = delete;

  /// The loopback port to connect to instead of the target.
  [[nodiscard]] int port() const { return port_; }

 private:
  void accept_loop();
  void pump(int client, int upstream);

  std::string source_;
  int target_port_ = 0;
  int listener_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread acceptor_;
  std::vector<std::thread> pumps_;  // touched by the acceptor thread only, joined after it
};

}  // namespace rfbsim::test
