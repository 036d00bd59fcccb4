// SPDX-License-Identifier: GPL-2.0-or-later
// Starting and stopping a session's process: no shell, its own process group, resource limits, an
// allow-listed environment without the manager's secrets, no core files, private files, output to the
// session's log file, and a readiness pipe on a known descriptor.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rfbsim::manager {

/// Resource limits for one process (0 = leave as inherited).
struct SpawnLimits {
  std::uint64_t address_space_bytes = 0;  ///< RLIMIT_AS
  std::uint64_t open_files = 0;           ///< RLIMIT_NOFILE
  std::uint64_t cpu_seconds = 0;          ///< RLIMIT_CPU (soft; hard = soft + 5 s, then SIGKILL)
};

/// An environment variable as (name, value).
using EnvVar = std::pair<std::string, std::string>;

/// What to start and how.
struct SpawnSpec {
  std::string program;             ///< path of the program (not searched in PATH)
  std::vector<std::string> args;   ///< arguments after the program name
  std::string working_dir;         ///< the session's folder; also the session's HOME unless `env` sets one
  std::string log_file;            ///< stdout and stderr go here (appended, created 0600 if needed)
  bool ready_pipe = true;          ///< give the child a pipe's write end as fd 3
  SpawnLimits limits;
  /// Variables set for the session on top of the allow-listed ones, replacing an inherited value of the same
  /// name: e.g. DISPLAY and XAUTHORITY for an X11 program. No secret's name (session_variable_problem).
  std::vector<EnvVar> env;
  /// Further names passed on from the manager's environment when set there (e.g. from the config:
  /// LD_LIBRARY_PATH), beyond kSessionVariables and RFBSIM_*. A secret's name is never passed.
  std::vector<std::string> pass_env;
};

/// The manager's variables a session inherits when they are set, besides RFBSIM_* ones: the search path,
/// the locale, the time zone, and the renderer's choice (which GPU or software renderer EGL uses).
extern const std::vector<std::string_view> kSessionVariables;

/// Why a session may not be given a variable called `name` ("" when it may): not a variable name (letters,
/// digits and '_', not starting with a digit), or a secret of the manager's (RFBSIM_ADMIN_TOKEN,
/// RFBSIM_LINK_SECRET, and any RFBSIM_ name with TOKEN, SECRET or PASSWORD in it, so that a secret added
/// later is kept by default). For config validation too.
std::string session_variable_problem(std::string_view name);

/// The environment a session gets, as NAME=value strings, from the manager's `inherited` one: the
/// variables of kSessionVariables, spec.pass_env and the RFBSIM_ prefix that are set there, never a
/// secret; PATH as the manager's or else /usr/local/bin:/usr/bin:/bin; HOME as spec.working_dir; then
/// spec.env, which replaces what it names. Pure. Throws std::invalid_argument naming a variable of
/// spec.env or spec.pass_env that session_variable_problem refuses, or a value of spec.env holding a NUL.
std::vector<std::string> session_environment(const std::vector<EnvVar>& inherited, const SpawnSpec& spec);

/// This process's environment now, as (name, value) pairs in its order.
std::vector<EnvVar> current_environment();

/// A started process.
struct SpawnedProcess {
  pid_t pid = -1;              ///< also its process group id
  int ready_fd = -1;           ///< read end of the readiness pipe (close-on-exec, non-blocking); -1 without
  std::int64_t start_ticks = 0;  ///< its start time (/proc/PID/stat), to recognise it after a restart
};

/// The child's descriptor for the readiness pipe's write end.
constexpr int kReadyFd = 3;

/// Forks and execs `spec.program`. The child leads a new process group, dies with the manager
/// (PR_SET_PDEATHSIG), gets the limits and RLIMIT_CORE 0 (no core file with a participant's data), umask
/// 077, session_environment(current_environment(), spec) as its whole environment, /dev/null as stdin,
/// the log (mode 0600) as stdout and stderr, and no other descriptor of ours. Throws std::runtime_error
/// naming the cause when the log cannot be opened or the program cannot be executed (e.g. "cannot run
/// /x/sim_rfb: No such file or directory"), std::invalid_argument for a refused variable in spec.
SpawnedProcess spawn_session_process(const SpawnSpec& spec);

/// Sends `signal` to the whole process group `pgid`; false if no such group is left.
bool signal_process_group(pid_t pgid, int signal);

/// The start time of process `pid` in clock ticks since boot (/proc/PID/stat field 22); nothing if it
/// does not exist.
std::optional<std::int64_t> process_start_ticks(pid_t pid);

/// Whether a process group still has a member that runs (zombies waiting to be reaped do not count).
bool process_group_alive(pid_t pgid);

}  // namespace rfbsim::manager
