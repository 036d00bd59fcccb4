// SPDX-License-Identifier: GPL-2.0-or-later
// Starting and stopping the launcher's two children (Xvnc and the session's program): fork and execve with an
// argv list (never a shell), in the launcher's process group, with a clean signal state and only the
// descriptors they are meant to have.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace rfbsim::x11 {

/// How to start one child.
struct ChildSpec {
  std::vector<std::string> argv;  ///< argv[0] is the program: a path, or a name searched in PATH when `search_path`
  std::vector<std::string> env;   ///< the whole environment, NAME=value
  bool search_path = false;       ///< look argv[0] up in PATH when it holds no '/'
  int output_fd = -1;             ///< becomes the child's stdout and stderr; -1: inherit ours
  int pass_fd = -1;               ///< kept open across the exec under its own number (e.g. -displayfd's pipe)
  int death_signal = 0;           ///< sent to the child when the launcher dies (PR_SET_PDEATHSIG); 0: none
};

/// Forks and execs `spec`. Waits until the exec has happened. Throws std::runtime_error naming the program and
/// the cause when it cannot be run (e.g. "cannot run /usr/bin/Xvnc: No such file or directory").
pid_t spawn_child(const ChildSpec& spec);

/// Waits for child `pid` until it exits or `deadline` passes, sleeping on `signal_fd` (a signalfd for SIGCHLD
/// and the stop signals; it is drained) between looks. Returns true with its wait status in `status`.
/// `stop_requested` is set when a SIGTERM, SIGINT or SIGHUP is read on the way.
bool wait_child_until(pid_t pid, std::chrono::steady_clock::time_point deadline, int signal_fd, int& status,
                      bool& stop_requested);

/// Stops child `pid`: SIGTERM, up to `grace` for it to exit, then SIGKILL and a wait. Returns its wait status.
int stop_child(pid_t pid, std::chrono::milliseconds grace, int signal_fd, bool& stop_requested);

/// Reads every pending signal from `signal_fd`; sets `stop_requested` on SIGTERM, SIGINT or SIGHUP.
void drain_signals(int signal_fd, bool& stop_requested);

}  // namespace rfbsim::x11
