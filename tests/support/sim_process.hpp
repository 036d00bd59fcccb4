// SPDX-License-Identifier: GPL-2.0-or-later
// SimProcess: runs a real sim_rfb process for a test and finds its port from the ready line.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace rfbsim::test {

class SimProcess {
 public:
  /// Starts `program` with `args` (no shell), and waits for its "ready: URL" line (http or https) on stdout.
  /// Throws std::runtime_error if it exits or stays silent past `timeout`.
  /// With `stderr_path`, the process's stderr is appended to that file (a test that reads the log); else it is
  /// this process's.
  SimProcess(const std::string& program, const std::vector<std::string>& args,
             std::chrono::milliseconds timeout = std::chrono::seconds(30), const std::string& stderr_path = {});
  /// Sends SIGKILL if the process still runs, and reaps it.
  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] const std::string& url() const { return url_; }
  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Whether the process is still running.
  [[nodiscard]] bool running();
  /// Sends `signal` and waits up to `timeout` for the exit; returns the exit status as from waitpid
  /// (WIFEXITED etc. apply), or -1 if it did not exit in time.
  int stop(int signal, std::chrono::milliseconds timeout = std::chrono::seconds(10));

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  int port_ = 0;
  std::string url_;
  bool reaped_ = false;
};

/// What a finished command did: its wait status (WIFEXITED etc.) and its stdout and stderr together.
struct ExitResult {
  int status = -1;  ///< -1 if it did not exit in time (it is then killed)
  std::string output;
};

/// Runs `program` with `args` (no shell) to completion, at most `timeout`.
ExitResult run_to_exit(const std::string& program, const std::vector<std::string>& args,
                       std::chrono::milliseconds timeout = std::chrono::seconds(30));

/// The path of the sim_rfb binary under test (from the RFBSIM_SIM_RFB environment variable or the
/// compiled-in default).
std::string sim_rfb_path();

}  // namespace rfbsim::test
