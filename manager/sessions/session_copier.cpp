// SPDX-License-Identifier: GPL-2.0-or-later
// SessionCopier: after-session copies, one command at a time, off the I/O thread.
#include "sessions/session_copier.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include "rfbsim/log.hpp"
#include "sessions/session.hpp"
#include "sessions/session_log.hpp"
#include "sessions/session_process.hpp"

namespace rfbsim::manager {

namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// How often a running command is looked at (its exit, its deadline, the copier stopping).
constexpr auto kPollInterval = std::chrono::milliseconds(50);

// The most of a command's last output line kept as the row's copy_error.
constexpr std::size_t kMaxErrorTail = 200;

// Variables a copy command may need beyond the sessions' allow-list: who it runs as, and where ssh (rsync) and
// rclone find their keys and configuration. HOME is the manager's (set through SpawnSpec::env), not a folder
// of ours as for a session.
const std::vector<std::string> kCopyVariables = {"USER", "LOGNAME", "SSH_AUTH_SOCK", "RCLONE_CONFIG",
                                                 "XDG_CONFIG_HOME"};

void log_copy(const CopyJob& job, const std::string& text) { log_about_session(job.session_id, job.uid, text); }

// The last non-empty line of `file` from byte `from` on (what this try's command wrote), at most
// kMaxErrorTail bytes of it.
std::string output_tail(const fs::path& file, std::streamoff from) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  const std::streamoff start = std::max(from, size - 4096);
  if (start >= size) return "";
  in.seekg(start);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  const std::size_t newline = text.rfind('\n');
  std::string line = newline == std::string::npos ? text : text.substr(newline + 1);
  if (line.size() > kMaxErrorTail) line = line.substr(line.size() - kMaxErrorTail);
  return line;
}

// The session folder's last component, also with a trailing '/'.
std::string folder_name_of(const fs::path& folder) {
  fs::path name = folder.filename();
  if (name.empty()) name = folder.parent_path().filename();
  return name.string();
}

}  // namespace

CopyJob copy_job_for(const Session& session) {
  CopyJob job;
  job.session_id = session.id;
  job.uid = session.uid;
  job.host = session.host_id;
  job.folder = session.data_path;
  job.attempts = session.copy_attempts;
  return job;
}

std::string find_program(const std::string& program, const std::string& path) {
  if (program.empty()) return "";
  if (program.find('/') != std::string::npos) return program;
  const std::string dirs = path.empty() ? "/usr/local/bin:/usr/bin:/bin" : path;
  std::size_t start = 0;
  for (;;) {
    const std::size_t colon = dirs.find(':', start);
    const std::string dir = dirs.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    // An empty entry means the working directory, which for a manager is an accident: skipped.
    if (!dir.empty()) {
      const std::string candidate = dir + "/" + program;
      struct stat info {};
      if (::stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) && ::access(candidate.c_str(), X_OK) == 0) {
        return candidate;
      }
    }
    if (colon == std::string::npos) return "";
    start = colon + 1;
  }
}

SessionCopier::SessionCopier(CopierSettings settings, Report report)
    : settings_(std::move(settings)), report_(std::move(report)), index_(settings_.index_path),
      thread_([this] { run(); }) {}

SessionCopier::~SessionCopier() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void SessionCopier::enqueue(CopyJob job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!known_.insert(job.session_id).second) return;
    queue_.push_back({std::move(job), Clock::now()});
  }
  wake_.notify_all();
}

bool SessionCopier::may_own(pid_t pid) {
  std::lock_guard<std::mutex> lock(mutex_);
  return spawning_ || (child_ > 0 && child_ == pid);
}

void SessionCopier::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return stopping_ || (queue_.empty() && !busy_); });
}

void SessionCopier::run() {
  for (;;) {
    CopyJob job;
    {
      // The job whose time has come first; copies waiting for their backoff let the others go by.
      std::unique_lock<std::mutex> lock(mutex_);
      for (;;) {
        if (stopping_) {
          idle_.notify_all();
          return;
        }
        if (queue_.empty()) {
          idle_.notify_all();
          wake_.wait(lock);
          continue;
        }
        const auto first = std::min_element(queue_.begin(), queue_.end(),
                                            [](const Waiting& a, const Waiting& b) { return a.due < b.due; });
        if (first->due <= Clock::now()) {
          job = std::move(first->job);
          queue_.erase(first);
          busy_ = true;
          break;
        }
        wake_.wait_until(lock, first->due);
      }
    }

    CopyOutcome outcome;
    const bool tried = try_once(job, outcome);
    if (tried) {
      // The row first, then the next try: the index never says less than what happened.
      try {
        index_.set_copy_status(outcome.session_id, outcome.state, outcome.attempts, outcome.error);
      } catch (const std::exception& error) {
        log_copy(job, std::string("cannot record the copy's outcome: ") + error.what());
      }
      const int tries = settings_.retries + 1;
      if (outcome.state == "done") {
        log_copy(job, "copied off this host (try " + std::to_string(outcome.attempts) + ")");
      } else if (outcome.state == "failed") {
        log_copy(job, "copy failed after " + std::to_string(outcome.attempts) + " tries, not tried again: " +
                          outcome.error);
      } else {
        log_copy(job, "copy try " + std::to_string(outcome.attempts) + " of " + std::to_string(tries) + " failed (" +
                          outcome.error + "); again in " + std::to_string(copy_backoff(outcome.attempts).count()) +
                          " s");
      }
      if (report_) report_(outcome);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      if (tried && outcome.state == "pending") {
        job.attempts = outcome.attempts;
        queue_.push_back({std::move(job), Clock::now() + copy_backoff(outcome.attempts)});
      } else if (tried) {
        known_.erase(job.session_id);
      }
      // Cut short by the copier stopping: the row stays 'pending' for the next manager.
    }
    idle_.notify_all();
  }
}

bool SessionCopier::try_once(const CopyJob& job, CopyOutcome& outcome) {
  outcome.session_id = job.session_id;
  outcome.attempts = job.attempts + 1;
  outcome.state = "pending";
  const int tries = settings_.retries + 1;
  const auto fail = [&](const std::string& error) {
    outcome.error = error;
    if (outcome.attempts >= tries) outcome.state = "failed";
    return true;
  };

  // A folder that is not there will not appear by trying again.
  const fs::path folder(job.folder);
  std::error_code ec;
  if (!folder.is_absolute() || !fs::is_directory(folder, ec)) {
    outcome.state = "failed";
    outcome.error = "the session folder " + job.folder + " is not there";
    return true;
  }
  const std::string folder_name = folder_name_of(folder);
  const CopyPlaceholders values{job.folder, folder_name, job.uid, job.host, std::to_string(job.session_id)};
  const std::vector<std::string> argv = substitute_copy_command(settings_.command, values);

  // The output log, beside the session folders and never in the one being copied.
  fs::create_directories(settings_.log_dir, ec);
  fs::permissions(settings_.log_dir, fs::perms::owner_all, fs::perm_options::replace, ec);
  const fs::path log_file = fs::path(settings_.log_dir) / (folder_name + ".log");
  std::streamoff output_from = 0;
  {
    const int fd = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
    if (fd < 0) return fail("cannot open the copy log " + log_file.string() + ": " + std::strerror(errno));
    std::string header = "--- try " + std::to_string(outcome.attempts) + " at " +
                         iso_utc(std::chrono::system_clock::now()) + ":";
    for (const std::string& arg : argv) header += " " + arg;
    header += "\n";
    [[maybe_unused]] const auto written = ::write(fd, header.data(), header.size());
    output_from = static_cast<std::streamoff>(::lseek(fd, 0, SEEK_END));
    ::close(fd);
  }

  const char* path_env = std::getenv("PATH");
  SpawnSpec spec;
  spec.program = find_program(argv.front(), path_env == nullptr ? "" : path_env);
  if (spec.program.empty()) return fail("cannot run " + argv.front() + ": not found in PATH");
  spec.args.assign(argv.begin() + 1, argv.end());
  spec.working_dir = settings_.log_dir;
  spec.log_file = log_file.string();
  spec.ready_pipe = false;
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') spec.env.emplace_back("HOME", home);
  spec.pass_env = kCopyVariables;

  // Started with the reaper told: until the pid is known, any exited child may be this one.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    spawning_ = true;
  }
  SpawnedProcess process;
  std::string spawn_error;
  try {
    process = spawn_session_process(spec);
  } catch (const std::exception& error) {
    spawn_error = error.what();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    spawning_ = false;
    child_ = process.pid;
  }
  if (!spawn_error.empty()) return fail(spawn_error);

  bool timed_out = false;
  const std::optional<int> status = wait_for_command(process.pid, timed_out);
  if (!status) return false;
  if (WIFEXITED(*status) && WEXITSTATUS(*status) == 0) {
    outcome.state = "done";
    outcome.error.clear();
    return true;
  }
  std::string error = describe_wait_status(*status);
  if (timed_out) error = "timed out after " + std::to_string(settings_.timeout.count()) + " s (" + error + ")";
  const std::string tail = output_tail(log_file, output_from);
  return fail(tail.empty() ? error : error + ": " + tail);
}

std::optional<int> SessionCopier::wait_for_command(pid_t pid, bool& timed_out) {
  const auto deadline = Clock::now() + settings_.timeout;
  std::optional<Clock::time_point> kill_at;
  bool killed = false;
  bool stopped = false;
  for (;;) {
    // Look before reaping: while the exited leader is a zombie its id cannot be reused, so the SIGKILL below
    // reaches only what the command left in its group (an ssh under rsync), never a stranger.
    siginfo_t info{};
    if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid) break;
    bool stop_now = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_now = stopping_;
    }
    const auto now = Clock::now();
    if (!kill_at && (now >= deadline || stop_now)) {
      timed_out = !stop_now;
      stopped = stop_now;
      signal_process_group(pid, SIGTERM);
      kill_at = now + settings_.kill_grace;
    } else if (kill_at && !killed && now >= *kill_at) {
      signal_process_group(pid, SIGKILL);
      killed = true;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait_for(lock, kPollInterval, [&] { return stopping_ && !kill_at; });
  }
  signal_process_group(pid, SIGKILL);
  int status = 0;
  pid_t reaped;
  do {
    reaped = ::waitpid(pid, &status, 0);
  } while (reaped < 0 && errno == EINTR);
  if (reaped != pid) status = 255 << 8;  // its exit was lost (cannot happen: nobody else waits for it): a failure
  bool stopping = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    child_ = -1;
    stopping = stopping_;
  }
  // Ended by the copier stopping (or failing while it stopped): not a try of its own; the next manager tries.
  const bool succeeded = reaped == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (stopped || (stopping && !succeeded)) return std::nullopt;
  return status;
}

}  // namespace rfbsim::manager
