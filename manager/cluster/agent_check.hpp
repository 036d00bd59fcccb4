// SPDX-License-Identifier: GPL-2.0-or-later
// HAProxy's agent-check: on each connection to a small port the manager writes one line that tells the
// balancer whether to send it new participants, and how many (a weight from its free slots), then closes.
// The line is a pure function of the load; the server only moves those bytes. HAProxy's configuration manual
// ("agent-check", section 5.2) documents the words: "up", "ready", "drain" and a percentage weight.
#pragma once

#include <boost/asio/io_context.hpp>
#include <functional>
#include <memory>
#include <string>

namespace rfbsim::manager {

/// What the agent reports: the manager's load and drain state at the moment a check connects.
struct AgentLoad {
  int free_slots = 0;          ///< session slots not in use
  int max_slots = 0;           ///< the configured max_sessions
  bool draining = false;       ///< the operator asked for no new participants (POST /api/drain)
  bool shutting_down = false;  ///< the manager is ending its sessions to stop
};

/// The agent's line: "up ready NN%\n" with NN = round(100 * free / max), at least 1, when a slot is free and the
/// host is neither draining nor shutting down; otherwise "drain\n" (live sessions still reach the host through
/// its own backend; only new uids go elsewhere).
std::string agent_status_line(const AgentLoad& load);

/// A listener that answers every connection with agent_status_line(load()) and closes it. Runs on `io`'s thread;
/// `load` is called there, once per connection. What a peer sends is never read.
class AgentCheckServer {
 public:
  /// Listens on `address` (numeric IPv4) and `port` (0 = any free port). Throws std::runtime_error naming the
  /// address and the cause (in use, bad address).
  AgentCheckServer(boost::asio::io_context& io, const std::string& address, int port,
                   std::function<AgentLoad()> load);
  ~AgentCheckServer();
  AgentCheckServer(const AgentCheckServer&) = delete;
  AgentCheckServer& operator=(const AgentCheckServer&) = delete;

  /// The port actually bound.
  [[nodiscard]] int port() const;
  /// Stops accepting; a line already being written still goes out.
  void stop();

 private:
  struct State;
  std::shared_ptr<State> state_;  // shared with pending handlers, which may outlive a stop()
};

}  // namespace rfbsim::manager
