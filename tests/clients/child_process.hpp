// SPDX-License-Identifier: GPL-2.0-or-later
// ChildProcess: a program we did not write (Xvfb, a VNC viewer, xdotool) run by a client test in a process group
// of its own, with its output in a log file; the group is stopped when the object goes, a failed check included.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace rfbsim::test {

/// How to start one child: no shell.
struct ChildSpec {
  std::vector<std::string> argv;       ///< argv[0] is a path or a name looked up in PATH
  std::vector<std::string> extra_env;  ///< NAME=value added to (or replacing in) this process's environment
  std::string log_path;                ///< stdout and stderr are appended here; empty: /dev/null
  int pass_fd = -1;                    ///< kept open across exec under its own number (Xvfb's -displayfd); -1: none
};

class ChildProcess {
 public:
  /// Forks and execs `spec`. Throws std::runtime_error when the fork fails; a program that cannot be run exits
  /// 127 at once (running() turns false, the log says why).
  explicit ChildProcess(const ChildSpec& spec);
  /// Stops the whole process group: SIGTERM, a short grace, then SIGKILL; reaps the child.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Whether the child has not exited yet (reaps it if it has).
  [[nodiscard]] bool running();

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
};

/// Runs `spec` to completion within `timeout` (killed past it) and returns its stdout and stderr together;
/// `status` gets the wait status (-1 when it was killed for the timeout).
std::string run_child(const ChildSpec& spec, int& status,
                      std::chrono::milliseconds timeout = std::chrono::seconds(20));

}  // namespace rfbsim::test
