// SPDX-License-Identifier: GPL-2.0-or-later
// SessionCopier: after a session's folder is final, the configured after_session_command copies it off this
// host (hosts are disposable; the study's data must outlive them), on a thread of its own.
//
// Why a thread: a copy to another machine takes seconds to minutes and the manager's one I/O thread carries
// every participant's relay. The I/O thread only queues a job; this thread runs one command at a time (never
// through a shell), with a per-try timeout (SIGTERM to the command's process group, SIGKILL after the grace
// period), and tries a failed copy again after a backoff (copy_backoff) while other sessions' copies go on.
// Each outcome is written to the session's index row (copy_state, copy_attempts, copy_error) through the
// copier's own SQLite connection before the next try, so a row never says less than what happened. A copy
// cut short by a manager stopping stays 'pending' and the next manager tries it again.
//
// Children: the copier starts and reaps its own command's process only (waitpid on that pid). The Supervisor's
// reaper, which may wait for any child, asks may_own() first and leaves the copier's child alone.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "sessions/copy_command.hpp"
#include "sessions/session_index.hpp"

namespace rfbsim::manager {

/// One session's folder to copy.
struct CopyJob {
  std::int64_t session_id = 0;
  std::string uid;
  std::string host;    ///< {host}: the manager's host_id
  std::string folder;  ///< the session's folder, absolute
  int attempts = 0;    ///< tries already made (from the index: a manager that restarts goes on counting)
};

/// How the copier runs; the defaults are the config's.
struct CopierSettings {
  std::vector<std::string> command;         ///< after_session_command, placeholders unreplaced (not empty)
  int retries = 5;                          ///< tries after the first that failed; then the copy is 'failed'
  std::chrono::seconds timeout{600};        ///< one try's limit, then SIGTERM to its process group
  std::chrono::seconds kill_grace{5};       ///< SIGKILL this long after the SIGTERM
  std::string index_path;                   ///< sessions.db; the copier opens its own connection
  /// The commands' output goes to <log_dir>/<folder_name>.log, appended, one file per session: never into the
  /// session folder being copied. Made (0700) when needed; also the commands' working directory.
  std::string log_dir;
};

/// What one try came to: the session row's copy columns after it.
struct CopyOutcome {
  std::int64_t session_id = 0;
  std::string state;  ///< "pending" (tried again later), "done" or "failed"
  int attempts = 0;   ///< tries so far
  std::string error;  ///< the last failure ("exit 23: rsync: ...", "timed out after 600 s"); "" when done
};

class SessionCopier {
 public:
  /// Called on the copier's thread after each try's outcome is in the index (may be empty).
  using Report = std::function<void(const CopyOutcome&)>;

  /// Opens the index (throws std::runtime_error like SessionIndex) and starts the thread.
  explicit SessionCopier(CopierSettings settings, Report report = nullptr);
  /// Stops a running try (SIGTERM, SIGKILL after kill_grace) without counting it, and leaves every copy not
  /// done 'pending' in the index for the next manager.
  ~SessionCopier();
  SessionCopier(const SessionCopier&) = delete;
  SessionCopier& operator=(const SessionCopier&) = delete;

  /// Queues a copy, to be tried at once (or after those before it); a session already queued is not queued twice.
  void enqueue(CopyJob job);

  /// Whether `pid` is, or may be, the copier's child: its running command, or any pid while one is being
  /// started (the pid is not known yet). Any thread. The Supervisor's reaper leaves such a pid alone.
  bool may_own(pid_t pid);

  /// Blocks until nothing is queued or running (tests). Copies waiting for their backoff count as queued.
  void drain();

 private:
  struct Waiting {
    CopyJob job;
    std::chrono::steady_clock::time_point due;
  };
  void run();
  // One try of `job`; false when it was cut short by the copier stopping (nothing to record).
  bool try_once(const CopyJob& job, CopyOutcome& outcome);
  // Waits for the command `pid` to exit and reaps it, enforcing the timeout; its wait status, or nothing when
  // the copier stopped it.
  std::optional<int> wait_for_command(pid_t pid, bool& timed_out);

  CopierSettings settings_;
  Report report_;
  SessionIndex index_;  // the copier's own connection, used on its thread only
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::vector<Waiting> queue_;
  std::set<std::int64_t> known_;  // sessions queued or being tried
  bool busy_ = false;             // a try is under way
  bool stopping_ = false;
  bool spawning_ = false;         // a command is being started: its pid is not known yet
  pid_t child_ = -1;              // the running command
  std::thread thread_;            // last: starts once everything above exists
};

/// The copy job of an ended session: its id, uid, host and folder, and the tries its row records.
CopyJob copy_job_for(const Session& session);

/// `program` as a path to execute: itself when it holds a '/', else the first executable file of that name in
/// `path` (a PATH value, ':'-separated, "" = /usr/local/bin:/usr/bin:/bin); "" when there is none.
std::string find_program(const std::string& program, const std::string& path);

}  // namespace rfbsim::manager
