// SPDX-License-Identifier: GPL-2.0-or-later
// Starting and stopping a session's process: no shell, its own process group, resource limits, output to
// the session's log file, and a readiness pipe on a known descriptor.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::manager {

/// Resource limits for one process (0 = leave as inherited).
struct SpawnLimits {
  std::uint64_t address_space_bytes = 0;  ///< RLIMIT_AS
  std::uint64_t open_files = 0;           ///< RLIMIT_NOFILE
  std::uint64_t cpu_seconds = 0;          ///< RLIMIT_CPU (soft; hard = soft + 5 s, then SIGKILL)
};

/// What to start and how.
struct SpawnSpec {
  std::string program;             ///< path of the program (not searched in PATH)
  std::vector<std::string> args;   ///< arguments after the program name
  std::string working_dir;         ///< the session's folder
  std::string log_file;            ///< stdout and stderr go here (appended, created if needed)
  bool ready_pipe = true;          ///< give the child a pipe's write end as fd 3
  SpawnLimits limits;
};

/// A started process.
struct SpawnedProcess {
  pid_t pid = -1;              ///< also its process group id
  int ready_fd = -1;           ///< read end of the readiness pipe (close-on-exec, non-blocking); -1 without
  std::int64_t start_ticks = 0;  ///< its start time (/proc/PID/stat), to recognise it after a restart
};

/// The child's descriptor for the readiness pipe's write end.
constexpr int kReadyFd = 3;

/// Forks and execs `spec.program`. The child leads a new process group, dies with the manager
/// (PR_SET_PDEATHSIG), gets the limits, /dev/null as stdin, the log as stdout and stderr, and no other
/// descriptor of ours. Throws std::runtime_error naming the cause when the log cannot be opened or the
/// program cannot be executed (e.g. "cannot run /x/sim_rfb: No such file or directory").
SpawnedProcess spawn_session_process(const SpawnSpec& spec);

/// Sends `signal` to the whole process group `pgid`; false if no such group is left.
bool signal_process_group(pid_t pgid, int signal);

/// The start time of process `pid` in clock ticks since boot (/proc/PID/stat field 22); nothing if it
/// does not exist.
std::optional<std::int64_t> process_start_ticks(pid_t pid);

/// Whether a process group still has a member that runs (zombies waiting to be reaped do not count).
bool process_group_alive(pid_t pgid);

}  // namespace rfbsim::manager
