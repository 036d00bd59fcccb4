// SPDX-License-Identifier: GPL-2.0-or-later
// What a sim_rfb session needs to serve its viewers and talk to its parent, a live session and a replay alike
// (main.cpp's run and replay_loop.cpp's run_replay): the server's options from the command line, the status
// document, the viewers' comings and goings, and the ready pipe's ready, outcome and stream lines.
#pragma once

#include <chrono>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "app/options.hpp"
#include "contract/ready_line.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"

namespace rfbsim::sim {

/// Tells the parent that the port is open: one line "ready <port>\n" on `fd` ("ready unix <path>\n" when
/// listening on a unix socket). The pipe stays open for the outcome line. Throws std::runtime_error when the
/// write fails (EPIPE: the parent left).
void report_ready(int fd, const rfbsim::Server& server);

/// The outcome line to the parent (sim_manager tells the survey); a parent that left is only logged.
void report_outcome(int fd, contract::TaskEnd end);

// The viewers' stream, told to the parent (sim_manager) on the ready pipe: a "stream ..." line about every second
// while someone watches, and "stream clients=0" once when the last viewer leaves (app/stream_status.hpp). A
// line is skipped rather than waited for when the pipe is full (a parent that stopped reading): the simulation
// thread never blocks on it. A parent that is gone ends the reports, with one word in the log.
class StreamReporter {
 public:
  static constexpr std::chrono::seconds kInterval{1};

  explicit StreamReporter(int fd) : fd_(fd) {}

  /// Called every loop with the viewers now: writes a line when one is due (see above).
  void update(std::chrono::steady_clock::time_point now, int clients, const rfbsim::Server& server);

 private:
  void write(const std::string& line);

  int fd_;
  bool watched_ = false;   // someone watched at the last update
  bool reported_ = false;  // a stream line was written since the last viewer came
  bool failed_ = false;
  std::chrono::steady_clock::time_point next_{};
};

// The latest status document, written by the simulation thread and read by HTTP workers.
class StatusBoard {
 public:
  void publish(std::string text) {
    std::lock_guard lock(mutex_);
    text_ = std::move(text);
  }
  std::string read() const {
    std::lock_guard lock(mutex_);
    return text_;
  }

 private:
  mutable std::mutex mutex_;
  std::string text_ = "{}";
};

// Viewers coming and going, told by the network thread and taken by the simulation thread, so that they
// are recorded at a tick like every other input.
class ClientChanges {
 public:
  struct Change {
    bool connected = false;
    rfbsim::ClientInfo client;
  };
  void push(bool connected, const rfbsim::ClientInfo& client) {
    std::lock_guard lock(mutex_);
    changes_.push_back({connected, client});
  }
  std::vector<Change> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(changes_, {});
  }

 private:
  std::mutex mutex_;
  std::vector<Change> changes_;
};

// The picture a session serves: its size in pixels and frames per second while watched.
struct Picture {
  int width = 0;
  int height = 0;
  int fps = 0;
};

/// The server as the command line asks for it, a live session's or a replay's alike: /status.json from
/// `status`, viewers coming and going into `client_changes` (addresses logged hashed with `address_key`). All
/// three must outlive the server. Throws std::runtime_error when no participant page is found.
rfbsim::ServerOptions server_options_of(const SimOptions& options, Picture picture, const StatusBoard& status,
                                        ClientChanges& client_changes, const std::string& address_key);

/// The off-screen renderer for `picture`, on the EGL platform the command line asks for.
rfbsim::OffscreenGLOptions gl_options_of(const SimOptions& options, Picture picture);

}  // namespace rfbsim::sim
