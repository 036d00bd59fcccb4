// SPDX-License-Identifier: GPL-2.0-or-later
// fork/exec of session processes. Between fork and exec the child of a multi-threaded parent may only make
// async-signal-safe calls, so every string and array is prepared before the fork.
#include "session_process.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace rfbsim::manager {

namespace {

// Closes a descriptor on scope exit unless released.
struct OwnedFd {
  int fd = -1;
  ~OwnedFd() {
    if (fd >= 0) ::close(fd);
  }
  int release() {
    const int out = fd;
    fd = -1;
    return out;
  }
};

// The child's part, async-signal-safe only. Reports a failure as an errno value on `error_fd` and exits.
[[noreturn]] void run_child(const SpawnSpec& spec, char* const* argv, int log_fd, int ready_write, int error_fd,
                            pid_t parent) {
  const auto fail = [error_fd](int stage) {
    const int code[2] = {stage, errno};
    [[maybe_unused]] const auto ignored = ::write(error_fd, code, sizeof code);
    ::_exit(127);
  };
  ::setpgid(0, 0);
  // Die with the manager, so that a manager killed with SIGKILL leaves no session behind. If it is
  // already gone (it died between fork and here), do not start at all.
  if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0) fail(1);
  if (::getppid() != parent) ::_exit(126);

  // Signals: the manager blocks or handles some; the session starts with a clean slate.
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  for (const int sig : {SIGPIPE, SIGINT, SIGTERM, SIGCHLD, SIGHUP}) ::sigaction(sig, &default_action, nullptr);

  const auto limit = [&](int resource, std::uint64_t soft, std::uint64_t hard) {
    if (soft == 0) return;
    const rlimit value{static_cast<rlim_t>(soft), static_cast<rlim_t>(hard)};
    if (::setrlimit(resource, &value) != 0) fail(2);
  };
  limit(RLIMIT_AS, spec.limits.address_space_bytes, spec.limits.address_space_bytes);
  limit(RLIMIT_NOFILE, spec.limits.open_files, spec.limits.open_files);
  limit(RLIMIT_CPU, spec.limits.cpu_seconds, spec.limits.cpu_seconds + 5);

  // Descriptors: 0 = /dev/null, 1 and 2 = the log, 3 = the readiness pipe, nothing else.
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (null_fd < 0 || ::dup2(null_fd, 0) < 0 || ::dup2(log_fd, 1) < 0 || ::dup2(log_fd, 2) < 0) fail(3);
  if (ready_write >= 0) {
    if (ready_write == kReadyFd) {
      if (::fcntl(kReadyFd, F_SETFD, 0) != 0) fail(3);  // keep it across exec
    } else if (::dup2(ready_write, kReadyFd) < 0) {
      fail(3);
    }
  }
  // The error pipe stays (close-on-exec: a successful exec closes it, which tells the parent).
  const int keep_below = ready_write >= 0 ? kReadyFd + 1 : kReadyFd;
  if (error_fd >= keep_below) {
    if (error_fd > keep_below) ::syscall(SYS_close_range, keep_below, error_fd - 1, 0);
    ::syscall(SYS_close_range, error_fd + 1, ~0U, 0);
  } else {
    fail(3);  // the error pipe must lie above the kept descriptors (guaranteed by the parent)
  }

  if (::chdir(spec.working_dir.c_str()) != 0) fail(4);
  ::execv(spec.program.c_str(), argv);
  fail(5);
  ::_exit(127);  // not reached: fail() exits
}

const char* stage_name(int stage) {
  switch (stage) {
    case 1: return "set the parent-death signal";
    case 2: return "set resource limits";
    case 3: return "set up descriptors";
    case 4: return "enter the session folder";
    default: return "run";
  }
}

// A descriptor at or above `floor`, close-on-exec, so that the child's dup2 targets never clash with it.
int move_above(int fd, int floor) {
  const int moved = ::fcntl(fd, F_DUPFD_CLOEXEC, floor);
  ::close(fd);
  return moved;
}

}  // namespace

SpawnedProcess spawn_session_process(const SpawnSpec& spec) {
  OwnedFd log{::open(spec.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0640)};
  if (log.fd < 0) throw std::runtime_error("cannot open the session log " + spec.log_file + ": " + std::strerror(errno));
  log.fd = move_above(log.fd, 10);

  OwnedFd ready_read, ready_write;
  if (spec.ready_pipe) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    ready_read.fd = fds[0];
    ready_write.fd = move_above(fds[1], 10);
  }
  int error_fds[2];
  if (::pipe2(error_fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  OwnedFd error_read{error_fds[0]};
  OwnedFd error_write{move_above(error_fds[1], 10)};
  if (log.fd < 0 || error_write.fd < 0 || (spec.ready_pipe && ready_write.fd < 0)) {
    throw std::runtime_error("out of file descriptors");
  }

  // argv, built before the fork.
  std::vector<std::string> strings;
  strings.push_back(spec.program);
  strings.insert(strings.end(), spec.args.begin(), spec.args.end());
  std::vector<char*> argv;
  for (std::string& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);

  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    // The error pipe must sit above every descriptor the child keeps; move_above(…, 10) made sure.
    run_child(spec, argv.data(), log.fd, ready_write.fd, error_write.fd, parent);
  }
  // Also here, so that the group exists before anyone signals it, whichever side runs first.
  ::setpgid(pid, pid);
  ::close(error_write.release());
  ::close(ready_write.release());

  // The exec succeeded when the error pipe closes without a word.
  int code[2] = {0, 0};
  ssize_t got;
  do {
    got = ::read(error_read.fd, code, sizeof code);
  } while (got < 0 && errno == EINTR);
  if (got == static_cast<ssize_t>(sizeof code)) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    // Name what failed: the folder when the child could not enter it, else the program.
    const std::string& subject = code[0] == 4 ? spec.working_dir : spec.program;
    throw std::runtime_error(std::string("cannot ") + stage_name(code[0]) + " " + subject + ": " +
                             std::strerror(code[1]));
  }

  SpawnedProcess out;
  out.pid = pid;
  out.start_ticks = process_start_ticks(pid).value_or(0);
  if (spec.ready_pipe) {
    ::fcntl(ready_read.fd, F_SETFL, ::fcntl(ready_read.fd, F_GETFL) | O_NONBLOCK);
    out.ready_fd = ready_read.release();
  }
  return out;
}

bool signal_process_group(pid_t pgid, int signal) {
  if (pgid <= 1) return false;  // never signal "every process" or init's group by mistake
  return ::kill(-pgid, signal) == 0;
}

namespace {

// The fields of a /proc/PID/stat file from field 3 (state) on; nothing if the process is gone. The command
// name (field 2) is in parentheses and may hold spaces, so fields are counted after the last ')'.
std::optional<std::vector<std::string>> stat_fields(const std::filesystem::path& stat_file) {
  std::ifstream stat(stat_file);
  std::string text;
  if (!std::getline(stat, text)) return std::nullopt;
  const std::size_t close = text.rfind(')');
  if (close == std::string::npos || close + 2 > text.size()) return std::nullopt;
  std::istringstream stream(text.substr(close + 2));
  std::vector<std::string> fields;
  for (std::string field; stream >> field;) fields.push_back(field);
  return fields;
}

// Indexes into stat_fields(): field N of proc(5) is at N - 3.
constexpr std::size_t kStateField = 0;        // field 3
constexpr std::size_t kGroupField = 2;        // field 5, pgrp
constexpr std::size_t kStartTimeField = 19;   // field 22, starttime in clock ticks

}  // namespace

bool process_group_alive(pid_t pgid) {
  if (pgid <= 1) return false;
  if (::kill(-pgid, 0) != 0 && errno != EPERM) return false;
  // The group exists, but zombies count too: a dead session whose new parent (init, after the manager
  // died) has not reaped it yet is gone for our purposes. Look for a member that still runs.
  const std::string group = std::to_string(pgid);
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc", ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const auto fields = stat_fields(it->path() / "stat");
    if (!fields || fields->size() <= kGroupField || (*fields)[kGroupField] != group) continue;
    const std::string& state = (*fields)[kStateField];
    if (state != "Z" && state != "X") return true;
  }
  return false;
}

std::optional<std::int64_t> process_start_ticks(pid_t pid) {
  const auto fields = stat_fields("/proc/" + std::to_string(pid) + "/stat");
  if (!fields || fields->size() <= kStartTimeField) return std::nullopt;
  std::int64_t ticks = 0;
  const std::string& text = (*fields)[kStartTimeField];
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), ticks);
  if (ec != std::errc() || ptr != text.data() + text.size()) return std::nullopt;
  return ticks;
}

}  // namespace rfbsim::manager
