// SPDX-License-Identifier: GPL-2.0-or-later
// What the Supervisor's source files share and nothing else includes: a live session's timers and readiness
// channel (Runtime), the SIGCHLD watch, and the session log line. The Supervisor is one class whose members
// are defined in supervisor.cpp (construction, the index, readiness, lookups), supervisor_start.cpp (starting
// a session) and supervisor_ending.cpp (ending, reaping, clean-up, the participant's presence).
#pragma once

#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <string>

#include "sessions/supervisor.hpp"
#include "rfbsim/log.hpp"
#include "sessions/session_log.hpp"

namespace rfbsim::manager {

// Per live session: its timers and its readiness channel.
struct Supervisor::Runtime {
  explicit Runtime(boost::asio::io_context& io)
      : expiry(io), idle(io), stop(io), start_deadline(io), poll(io), ready_pipe(io), probe(io) {}
  boost::asio::steady_timer expiry, idle, stop, start_deadline, poll;
  boost::asio::posix::stream_descriptor ready_pipe;
  boost::asio::ip::tcp::socket probe;  // kRfb: tries the port until it answers
  std::array<char, 256> buffer{};
  std::string ready_text;
  bool bad_stream_logged = false;  // a bad stream line is logged once per session, not every second
  int clients = 0;
  bool ever_connected = false;  // a participant's browser connected at least once
  int x11_display = -1;         // kX11: the display rfbsim_x11_session reported, cleaned after a SIGKILL
  std::chrono::steady_clock::time_point started;
};

struct Supervisor::ChildWatch {
  explicit ChildWatch(boost::asio::io_context& io) : signals(io, SIGCHLD) {}
  boost::asio::signal_set signals;
};

/// One line of the manager's log about `session`.
inline void log_session(const Session& session, const std::string& text) {
  log_about_session(session.id, session.uid, text);
}

}  // namespace rfbsim::manager
