// SPDX-License-Identifier: GPL-2.0-or-later
// fork/exec for the launcher's children. The launcher has one thread, but the child still makes only simple
// system calls between fork and exec: everything it needs is built before the fork.
#include "child_process.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>

#include "child_signals.hpp"

namespace rfbsim::x11 {

namespace {

std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> out;
  for (std::string& s : strings) out.push_back(s.data());
  out.push_back(nullptr);
  return out;
}

// The child's part: reports a failed exec's errno on `error_fd` and exits 127.
[[noreturn]] void run_child(const ChildSpec& spec, char* const* argv, char* const* envp, int error_fd, pid_t parent) {
  // The launcher blocks its signals for its signalfd and ignores SIGPIPE; the child starts clean (a blocked or
  // ignored signal would survive the exec).
  rfbsim::x11::reset_signals_for_exec();

  // Do not outlive the launcher: its clean-up would never run for us.
  if (spec.death_signal != 0) {
    ::prctl(PR_SET_PDEATHSIG, spec.death_signal);
    if (::getppid() != parent) ::_exit(126);
  }
  if (spec.output_fd >= 0 && (::dup2(spec.output_fd, 1) < 0 || ::dup2(spec.output_fd, 2) < 0)) {
    const int error = errno;
    [[maybe_unused]] const auto ignored = ::write(error_fd, &error, sizeof error);
    ::_exit(127);
  }
  // Nothing of ours or of our parent's beyond 0..2 and the one descriptor handed on: everything else is
  // marked close-on-exec (the error pipe must live until the exec itself).
  const unsigned pass = spec.pass_fd >= 3 ? static_cast<unsigned>(spec.pass_fd) : 0U;
  const bool marked = pass == 0 ? ::syscall(SYS_close_range, 3U, ~0U, CLOSE_RANGE_CLOEXEC) == 0
                                : (pass == 3 || ::syscall(SYS_close_range, 3U, pass - 1, CLOSE_RANGE_CLOEXEC) == 0) &&
                                      ::syscall(SYS_close_range, pass + 1, ~0U, CLOSE_RANGE_CLOEXEC) == 0;
  if (!marked) {  // a kernel before 5.11: one descriptor at a time
    const long open_max = std::min(::sysconf(_SC_OPEN_MAX), 65536L);
    for (int fd = 3; fd < open_max; ++fd) {
      if (fd != spec.pass_fd) ::fcntl(fd, F_SETFD, FD_CLOEXEC);
    }
  }
  if (spec.pass_fd >= 0) ::fcntl(spec.pass_fd, F_SETFD, 0);  // the one descriptor handed on
  if (spec.search_path) {
    ::execvpe(argv[0], argv, envp);
  } else {
    ::execve(argv[0], argv, envp);
  }
  const int error = errno;
  [[maybe_unused]] const auto ignored = ::write(error_fd, &error, sizeof error);
  ::_exit(127);
}

bool is_stop_signal(std::uint32_t signo) {
  return signo == SIGTERM || signo == SIGINT || signo == SIGHUP;
}

}  // namespace

pid_t spawn_child(const ChildSpec& spec) {
  if (spec.argv.empty() || spec.argv.front().empty()) throw std::runtime_error("no program to run");
  std::vector<std::string> argv_strings = spec.argv;
  std::vector<std::string> env_strings = spec.env;
  const std::vector<char*> argv = pointers(argv_strings);
  const std::vector<char*> envp = pointers(env_strings);

  // The exec succeeded when this pipe (close-on-exec) closes without a word.
  int error_pipe[2];
  if (::pipe2(error_pipe, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(error_pipe[0]);
    ::close(error_pipe[1]);
    throw std::runtime_error(std::string("fork: ") + std::strerror(error));
  }
  if (pid == 0) run_child(spec, argv.data(), envp.data(), error_pipe[1], parent);
  ::close(error_pipe[1]);

  int error = 0;
  ssize_t got;
  do {
    got = ::read(error_pipe[0], &error, sizeof error);
  } while (got < 0 && errno == EINTR);
  ::close(error_pipe[0]);
  if (got == static_cast<ssize_t>(sizeof error)) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    throw std::runtime_error("cannot run " + spec.argv.front() + ": " + std::strerror(error));
  }
  return pid;
}

void drain_signals(int signal_fd, bool& stop_requested) {
  signalfd_siginfo info{};
  while (::read(signal_fd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
    if (is_stop_signal(info.ssi_signo)) stop_requested = true;
  }
}

bool wait_child_until(pid_t pid, std::chrono::steady_clock::time_point deadline, int signal_fd, int& status,
                      bool& stop_requested) {
  for (;;) {
    const pid_t got = ::waitpid(pid, &status, WNOHANG);
    if (got == pid) return true;
    if (got < 0 && errno != EINTR) {
      status = 0;  // not our child (any more): nothing to wait for
      return true;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    // SIGCHLD wakes the poll; the cap only bounds a missed wake-up.
    pollfd watch{signal_fd, POLLIN, 0};
    ::poll(&watch, 1, static_cast<int>(std::min<std::chrono::milliseconds::rep>(left.count(), 200)));
    drain_signals(signal_fd, stop_requested);
  }
}

int stop_child(pid_t pid, std::chrono::milliseconds grace, int signal_fd, bool& stop_requested) {
  int status = 0;
  ::kill(pid, SIGTERM);
  if (wait_child_until(pid, std::chrono::steady_clock::now() + grace, signal_fd, status, stop_requested)) {
    return status;
  }
  ::kill(pid, SIGKILL);
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

}  // namespace rfbsim::x11
