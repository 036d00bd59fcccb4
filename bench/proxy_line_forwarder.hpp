// SPDX-License-Identifier: GPL-2.0-or-later
// A loopback TCP forwarder that opens each connection to its target with a PROXY protocol v1 line, as
// sim_manager's relay does: sim_rfb sessions started by the manager (--proxy-protocol) close any connection
// that does not begin with one. bench_manager's table 2 reaches a session's own port through it.
#pragma once

#include <atomic>
#include <list>
#include <mutex>
#include <thread>

namespace rfbsim::bench {

/// Listens on 127.0.0.1 at an ephemeral port; each accepted connection is connected to 127.0.0.1:target_port,
/// sent "PROXY TCP4 <client> 127.0.0.1 <client port> <target port>\r\n", then relayed both ways unchanged
/// until either side closes. One thread per connection; meant for a few connections.
class ProxyLineForwarder {
 public:
  /// Starts listening; throws std::runtime_error when the listening socket cannot be set up.
  explicit ProxyLineForwarder(int target_port);
  /// Stops accepting, closes every connection and joins the threads (within about 200 ms).
  ~ProxyLineForwarder();
  ProxyLineForwarder(const ProxyLineForwarder&) = delete;
  ProxyLineForwarder& operator=(const ProxyLineForwarder&) = delete;

  /// The loopback port to connect to.
  [[nodiscard]] int port() const { return port_; }

 private:
  void accept_loop();
  void relay(int client);  // one connection's loop, on its own thread

  int target_port_;
  int listener_ = -1;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;
  std::list<std::thread> connections_;  // under mutex_
  std::thread acceptor_;
};

}  // namespace rfbsim::bench
