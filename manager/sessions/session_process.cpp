// SPDX-License-Identifier: GPL-2.0-or-later
// fork/exec of session processes. Between fork and exec the child of a multi-threaded parent may only make
// async-signal-safe calls, so every string and array is prepared before the fork.
#include "sessions/session_process.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "child_signals.hpp"

extern char** environ;

namespace rfbsim::manager {

const std::vector<std::string_view> kSessionVariables = {
    "PATH", "LANG", "LC_ALL", "TZ",
    // The renderer: an admin who points the manager at a GPU or at Mesa's software renderer means its
    // sessions too (sim_rfb draws with EGL; llvmpipe reads LP_NUM_THREADS).
    "EGL_PLATFORM", "LIBGL_ALWAYS_SOFTWARE", "GALLIUM_DRIVER", "MESA_LOADER_DRIVER_OVERRIDE", "LP_NUM_THREADS",
    "__EGL_VENDOR_LIBRARY_FILENAMES", "__EGL_VENDOR_LIBRARY_DIRS"};

namespace {

constexpr std::string_view kRfbsimPrefix = "RFBSIM_";
constexpr const char* kFallbackPath = "/usr/local/bin:/usr/bin:/bin";

bool starts_with(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }

}  // namespace

std::string session_variable_problem(std::string_view name) {
  const auto letter = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  bool valid = !name.empty() && letter(name.front());
  for (const char c : name) valid = valid && (letter(c) || digit(c));
  if (!valid) return "'" + std::string(name) + "' is not an environment variable name";
  // The deny rule beats every allow rule, the RFBSIM_ prefix included: the manager's own secrets (which
  // config.cpp also reads from the environment) must never reach a participant's process.
  const bool secret = name == "RFBSIM_ADMIN_TOKEN" || name == "RFBSIM_LINK_SECRET" ||
                      (starts_with(name, kRfbsimPrefix) && (name.find("TOKEN") != std::string_view::npos ||
                                                            name.find("SECRET") != std::string_view::npos ||
                                                            name.find("PASSWORD") != std::string_view::npos));
  if (secret) return std::string(name) + " is a secret of the manager's and never given to a session";
  return "";
}

std::vector<std::string> session_environment(const std::vector<EnvVar>& inherited, const SpawnSpec& spec) {
  // What the caller asks for is checked first: a refused name there is a mistake to report, not to drop.
  for (const std::string& name : spec.pass_env) {
    if (const std::string problem = session_variable_problem(name); !problem.empty()) {
      throw std::invalid_argument("session environment: " + problem);
    }
  }
  for (const auto& [name, value] : spec.env) {
    if (const std::string problem = session_variable_problem(name); !problem.empty()) {
      throw std::invalid_argument("session environment: " + problem);
    }
    if (value.find('\0') != std::string::npos) {
      throw std::invalid_argument("session environment: the value of " + name + " holds a NUL byte");
    }
  }
  const auto named_in = [](const auto& list, std::string_view name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  const auto set_by_spec = [&](std::string_view name) {
    return std::any_of(spec.env.begin(), spec.env.end(), [&](const EnvVar& var) { return var.first == name; });
  };

  // The manager's allow-listed variables, in its order, each once (the first, as getenv finds it).
  std::vector<std::string> out;
  std::vector<std::string_view> taken;
  for (const auto& [name, value] : inherited) {
    const bool allowed =
        named_in(kSessionVariables, name) || named_in(spec.pass_env, name) || starts_with(name, kRfbsimPrefix);
    if (!allowed || name == "HOME" || set_by_spec(name) || named_in(taken, name)) continue;
    if (!session_variable_problem(name).empty()) continue;
    taken.push_back(name);
    out.push_back(name + "=" + value);
  }
  // Programs and the shells they start look for PATH; without the manager's, a usual one.
  if (!named_in(taken, "PATH") && !set_by_spec("PATH")) out.push_back(std::string("PATH=") + kFallbackPath);
  // HOME is the session's folder, not the manager's: dotfiles and caches a program writes stay with that
  // session, and no session reads what an earlier participant's left in a shared home.
  if (!set_by_spec("HOME") && !spec.working_dir.empty()) out.push_back("HOME=" + spec.working_dir);
  for (const auto& [name, value] : spec.env) out.push_back(name + "=" + value);
  return out;
}

std::vector<EnvVar> current_environment() {
  std::vector<EnvVar> out;
  for (char** entry = environ; entry != nullptr && *entry != nullptr; ++entry) {
    const std::string_view text(*entry);
    const std::size_t equals = text.find('=');
    if (equals == std::string_view::npos) continue;  // not NAME=value: nothing a session could use
    out.emplace_back(std::string(text.substr(0, equals)), std::string(text.substr(equals + 1)));
  }
  return out;
}

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
[[noreturn]] void run_child(const SpawnSpec& spec, char* const* argv, char* const* envp, int log_fd, int ready_write,
                            int error_fd, pid_t parent) {
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
  rfbsim::x11::reset_signals_for_exec();

  // Never above the hard limit we inherited: without privileges raising it fails, and a limit lower than asked
  // for is still a limit (a manager under `ulimit -Hn 512` must still start sessions).
  const auto limit = [&](int resource, std::uint64_t soft, std::uint64_t hard) {
    if (soft == 0) return;
    rlimit inherited{};
    if (::getrlimit(resource, &inherited) != 0) fail(2);
    const auto cap = [&](std::uint64_t value) {
      const auto wanted = static_cast<rlim_t>(value);
      return inherited.rlim_max == RLIM_INFINITY || wanted <= inherited.rlim_max ? wanted : inherited.rlim_max;
    };
    const rlimit value{cap(soft), cap(hard)};
    if (::setrlimit(resource, &value) != 0) fail(2);
  };
  limit(RLIMIT_AS, spec.limits.address_space_bytes, spec.limits.address_space_bytes);
  limit(RLIMIT_NOFILE, spec.limits.open_files, spec.limits.open_files);
  limit(RLIMIT_CPU, spec.limits.cpu_seconds, spec.limits.cpu_seconds + 5);
  // No core files, soft and hard: a crashed session's memory holds a participant's data.
  const rlimit no_core{0, 0};
  if (::setrlimit(RLIMIT_CORE, &no_core) != 0) fail(2);
  // What the session creates (its recordings, its own logs) is the manager user's alone.
  ::umask(077);

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
  ::execve(spec.program.c_str(), argv, envp);
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
  // The environment first: a refused variable is the caller's mistake, found before anything is opened.
  std::vector<std::string> env_strings = session_environment(current_environment(), spec);

  // The log may hold what a participant typed or an error quoting the session's data: owner only, also
  // when an earlier run left it with wider permissions.
  OwnedFd log{::open(spec.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600)};
  if (log.fd < 0) throw std::runtime_error("cannot open the session log " + spec.log_file + ": " + std::strerror(errno));
  struct stat log_stat {};
  if (::fstat(log.fd, &log_stat) == 0 && S_ISREG(log_stat.st_mode) && (log_stat.st_mode & 077) != 0) {
    ::fchmod(log.fd, 0600);
  }
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
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);

  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    // The error pipe must sit above every descriptor the child keeps; move_above(…, 10) made sure.
    run_child(spec, argv.data(), envp.data(), log.fd, ready_write.fd, error_write.fd, parent);
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
