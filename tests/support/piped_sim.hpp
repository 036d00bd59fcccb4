// SPDX-License-Identifier: GPL-2.0-or-later
// Test helper: sim_rfb started as sim_manager starts it, with --ready-fd 3 on a pipe the test reads, and
// extra environment variables (a test fault). Its output goes to a log file the test can read.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace rfbsim::test {

class PipedSim {
 public:
  /// Starts `program` with `args` plus "--ready-fd 3", `env` added to the environment, stdout and stderr
  /// to `log`. Throws std::runtime_error when it cannot start.
  PipedSim(const std::string& program, std::vector<std::string> args,
           const std::vector<std::pair<std::string, std::string>>& env, const std::filesystem::path& log);
  /// SIGKILL if still running, reaped.
  ~PipedSim();
  PipedSim(const PipedSim&) = delete;
  PipedSim& operator=(const PipedSim&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Reads the pipe until a whole line starting with `prefix` arrives (returned without its newline), the
  /// pipe ends or `timeout` passes (then ""). Every line read is kept in lines().
  std::string await_line(const std::string& prefix, std::chrono::milliseconds timeout);
  /// Every whole line read from the pipe so far, with its newline.
  [[nodiscard]] const std::vector<std::string>& lines() const { return lines_; }
  /// Sends `signal`, reads the pipe to its end, and returns the wait status (-1 if no exit within `timeout`).
  int stop(int signal, std::chrono::milliseconds timeout = std::chrono::seconds(20));

 private:
  bool read_some(std::chrono::milliseconds timeout);  // false: the pipe ended or nothing came in time

  pid_t pid_ = -1;
  int pipe_fd_ = -1;
  bool reaped_ = false;
  std::string partial_;
  std::vector<std::string> lines_;
};

}  // namespace rfbsim::test
