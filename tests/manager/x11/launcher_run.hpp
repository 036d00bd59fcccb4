// SPDX-License-Identifier: GPL-2.0-or-later
// A real rfbsim_x11_session process for the tests, started as sim_manager starts it: its own process group,
// the session folder as working directory, a ready pipe as fd 3, stdout on a pipe the test reads.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::test {

/// The launcher built here, and the key-echo program ("" when X11 was not found at build time).
extern const char* const kX11SessionBinary;
extern const char* const kKeyEchoBinary;

/// The Xvnc the launcher runs: $RFBSIM_XVNC where set (a test of the skips points it at a missing file), else
/// Debian's /usr/bin/Xvnc.
std::string xvnc_path();

/// "" when Xvnc and the key-echo program exist, so that a process test can run; else what is missing.
std::string x11_missing();

class LauncherRun {
 public:
  /// Starts `launcher_args` (flags before "--", --ready-fd 3 added, and --xvnc xvnc_path() unless they name
  /// one) and `program` after "--", in `folder`.
  /// Throws std::runtime_error when it cannot be started.
  LauncherRun(const std::string& folder, const std::vector<std::string>& launcher_args,
              const std::vector<std::string>& program);
  /// SIGKILLs what is left of its group and reaps the launcher.
  ~LauncherRun();
  LauncherRun(const LauncherRun&) = delete;
  LauncherRun& operator=(const LauncherRun&) = delete;

  /// The launcher's pid, also its process group.
  [[nodiscard]] pid_t pid() const { return pid_; }

  /// Everything on the ready pipe once it has closed; nothing if it is still open after `timeout`. It closes
  /// only when the launcher has closed it and neither Xvnc nor the program holds a copy.
  std::optional<std::string> ready_text(std::chrono::milliseconds timeout);
  /// Reads stdout until a line equal to `line` has come (true) or `timeout` passes (false).
  bool wait_for_line(const std::string& line, std::chrono::milliseconds timeout);
  /// Everything read from stdout so far.
  [[nodiscard]] const std::string& output() const { return output_; }

  /// Waits for the launcher's exit; its wait status, or nothing after `timeout`.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int ready_fd_ = -1;
  int stdout_fd_ = -1;
  std::string output_;
};

/// Whether any process of group `pgid` runs (zombies do not count).
bool group_has_live_member(pid_t pgid);

/// The pids of `pid`'s children (/proc/PID/task/PID/children).
std::vector<pid_t> children_of(pid_t pid);

/// Whether a file (of any kind, a dangling link too) exists at `path`.
bool path_exists(const std::string& path);

}  // namespace rfbsim::test
