// SPDX-License-Identifier: GPL-2.0-or-later
// ProcessLauncher: session processes are started on a thread of their own.
//
// Why: a start makes the session's folder and forks and execs its program, then waits until the exec has
// happened (to name a missing program at once). A fork copies the manager's page tables and an exec may wait on
// a slow disk: milliseconds, far more on a loaded machine, and the manager's one I/O thread carries every
// participant's relay. So the I/O thread queues the job and goes on; this thread runs the jobs in order and
// reports each through a callback on its own thread (the caller posts it back).
//
// The thread lives as long as the launcher: a child started with PR_SET_PDEATHSIG dies when the *thread* that
// forked it ends, so the launcher must outlive every session it started.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "sessions/session_process.hpp"

namespace rfbsim::manager {

/// What to make and start for one session.
struct LaunchJob {
  std::string folder;  ///< made (with parents) before the start; the session's data folder
  SpawnSpec spec;
};

/// How a launch went: the process, or why there is none.
struct LaunchResult {
  SpawnedProcess process;  ///< pid -1 when `error` says why
  std::string error;
};

class ProcessLauncher {
 public:
  /// Called on the launcher's thread with the job's result.
  using Done = std::function<void(LaunchResult)>;

  ProcessLauncher();
  /// Finishes the start under way, drops those not begun (no one would watch over them), and stops.
  ~ProcessLauncher();
  ProcessLauncher(const ProcessLauncher&) = delete;
  ProcessLauncher& operator=(const ProcessLauncher&) = delete;

  /// Queues `job`; `done` gets its result on the launcher's thread.
  void launch(LaunchJob job, Done done);

 private:
  struct Queued {
    LaunchJob job;
    Done done;
  };
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Queued> jobs_;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once everything above exists
};

/// Makes `job.folder` and starts `job.spec` (spawn_session_process). Never throws: a failure is the result's
/// error, e.g. "cannot run /x/sim_rfb: No such file or directory".
LaunchResult run_launch(const LaunchJob& job);

}  // namespace rfbsim::manager
