// SPDX-License-Identifier: GPL-2.0-or-later
// LauncherRun: fork/exec of rfbsim_x11_session with pipes the test reads without blocking past a deadline.
#include "launcher_run.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace rfbsim::test {

const char* const kX11SessionBinary = RFBSIM_X11_SESSION;
const char* const kKeyEchoBinary = RFBSIM_X11_KEY_ECHO;

namespace {

using Clock = std::chrono::steady_clock;

// Appends what `fd` has to `out`, waiting up to `left`; false at end of file.
bool read_some(int fd, std::string& out, std::chrono::milliseconds left) {
  pollfd watch{fd, POLLIN, 0};
  if (::poll(&watch, 1, static_cast<int>(std::max<std::chrono::milliseconds::rep>(left.count(), 0))) <= 0) return true;
  char buffer[4096];
  const ssize_t n = ::read(fd, buffer, sizeof buffer);
  if (n > 0) out.append(buffer, static_cast<std::size_t>(n));
  return n > 0 || (n < 0 && errno == EINTR);
}

std::chrono::milliseconds left_until(Clock::time_point deadline) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
}

}  // namespace

std::string xvnc_path() {
  const char* chosen = std::getenv("RFBSIM_XVNC");
  return chosen != nullptr && *chosen != '\0' ? chosen : "/usr/bin/Xvnc";
}

std::string x11_missing() {
  if (const std::string xvnc = xvnc_path(); ::access(xvnc.c_str(), X_OK) != 0) {
    return xvnc + " is missing (apt-get install tigervnc-standalone-server)";
  }
  if (std::string(kKeyEchoBinary).empty()) return "rfbsim_x11_key_echo was not built (libx11-dev missing)";
  return "";
}

LauncherRun::LauncherRun(const std::string& folder, const std::vector<std::string>& launcher_args,
                         const std::vector<std::string>& program) {
  std::vector<std::string> args{kX11SessionBinary, "--ready-fd", "3"};
  // The chosen Xvnc, unless the test names its own (the launcher takes each flag once).
  if (std::find(launcher_args.begin(), launcher_args.end(), "--xvnc") == launcher_args.end()) {
    args.insert(args.end(), {"--xvnc", xvnc_path()});
  }
  args.insert(args.end(), launcher_args.begin(), launcher_args.end());
  args.emplace_back("--");
  args.insert(args.end(), program.begin(), program.end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);

  int ready[2];
  int out[2];
  if (::pipe2(ready, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  // Signals stay blocked across the fork: a SIGTERM that a test sends at once must find the child with the
  // default action (as sim_manager's children start), never Catch's handler that the fork copied.
  sigset_t all;
  sigset_t before;
  sigfillset(&all);
  ::pthread_sigmask(SIG_SETMASK, &all, &before);
  pid_ = ::fork();
  if (pid_ == 0) {
    struct sigaction default_action {};
    default_action.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) ::sigaction(sig, &default_action, nullptr);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    // As sim_manager does it: a group of its own, the session folder, fd 3 for the ready lines.
    ::setpgid(0, 0);
    if (::chdir(folder.c_str()) != 0) ::_exit(126);
    ::dup2(out[1], 1);
    ::dup2(ready[1], 3);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
  if (pid_ < 0) throw std::runtime_error("fork failed");
  ::setpgid(pid_, pid_);
  ::close(ready[1]);
  ::close(out[1]);
  ready_fd_ = ready[0];
  stdout_fd_ = out[0];
}

LauncherRun::~LauncherRun() {
  if (!reaped_) {
    ::kill(-pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  ::close(ready_fd_);
  ::close(stdout_fd_);
}

std::optional<std::string> LauncherRun::ready_text(std::chrono::milliseconds timeout) {
  std::string text;
  const auto deadline = Clock::now() + timeout;
  while (read_some(ready_fd_, text, left_until(deadline))) {
    if (left_until(deadline).count() <= 0) return std::nullopt;
  }
  return text;
}

bool LauncherRun::wait_for_line(const std::string& line, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    std::istringstream lines(output_);
    for (std::string got; std::getline(lines, got);) {
      if (got == line) return true;
    }
    if (left_until(deadline).count() <= 0 || !read_some(stdout_fd_, output_, left_until(deadline))) return false;
  }
}

std::optional<int> LauncherRun::wait_exit(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  int status = 0;
  while (::waitpid(pid_, &status, WNOHANG) != pid_) {
    if (left_until(deadline).count() <= 0) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  reaped_ = true;
  return status;
}

bool group_has_live_member(pid_t pgid) {
  const std::string group = std::to_string(pgid);
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string text;
    if (!std::getline(stat, text)) continue;
    // Fields after the command name (in parentheses, maybe with spaces): state, ppid, pgrp.
    std::istringstream fields(text.substr(text.rfind(')') + 2));
    std::string state, ppid, pgrp;
    fields >> state >> ppid >> pgrp;
    if (pgrp == group && state != "Z" && state != "X") return true;
  }
  return false;
}

std::vector<pid_t> children_of(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  std::vector<pid_t> out;
  for (pid_t child = 0; in >> child;) out.push_back(child);
  return out;
}

bool path_exists(const std::string& path) {
  struct stat info {};
  return ::lstat(path.c_str(), &info) == 0;
}

}  // namespace rfbsim::test
