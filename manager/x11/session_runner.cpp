// SPDX-License-Identifier: GPL-2.0-or-later
// The launcher's single thread: every wait is a poll on a signalfd (SIGCHLD and the stop signals) and, while
// Xvnc starts, on its -displayfd pipe. Children are looked at with waitpid(WNOHANG) on every wake-up, so a
// SIGCHLD merged with another is never lost.
#include "session_runner.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "contract/ready_line.hpp"
#include "child_process.hpp"
#include "rfbsim/log.hpp"
#include "x11_display.hpp"
#include "xauthority.hpp"
#include "xvnc_command.hpp"

extern char** environ;

namespace rfbsim::x11 {

namespace {

using std::chrono::steady_clock;

constexpr std::chrono::seconds kXvncStartTimeout{10};      // measured: ~0.3 s on an idle machine
constexpr std::chrono::milliseconds kProgramGrace{2000};   // SIGTERM to SIGKILL for the program
constexpr std::chrono::milliseconds kXvncGrace{2000};      // and for Xvnc
constexpr const char* kXvncLog = "xvnc.log";

constexpr const char* kLogTag = "rfbsim_x11_session";

// Most of what the launcher says is an error (it says nothing while all goes well), through the log sink.
void say(const std::string& line) { log::write(log::Level::kError, kLogTag, line); }

// A descriptor closed at scope exit.
struct Fd {
  int fd = -1;
  Fd() = default;
  explicit Fd(int value) : fd(value) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() { reset(); }
  void reset() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

// What the session made, removed at scope exit whatever way the session ends.
struct Leftovers {
  std::string xauthority;
  std::string rfb_socket;
  int display = -1;
  Leftovers(std::string xauthority_path, std::string rfb_socket_path)
      : xauthority(std::move(xauthority_path)), rfb_socket(std::move(rfb_socket_path)) {}
  Leftovers(const Leftovers&) = delete;
  Leftovers& operator=(const Leftovers&) = delete;
  ~Leftovers() {
    ::unlink(xauthority.c_str());
    // Only a socket: whatever else sits at that path is not ours to remove.
    struct stat info {};
    if (::lstat(rfb_socket.c_str(), &info) == 0 && S_ISSOCK(info.st_mode)) ::unlink(rfb_socket.c_str());
    if (display >= 0 && !remove_stale_display(display)) {
      log::write(log::Level::kWarn, kLogTag,
                 "display :" + std::to_string(display) + " is still held by a live server; its files stay");
    }
  }
};

bool write_all(int fd, const std::string& text) {
  for (std::size_t written = 0; written < text.size();) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<std::size_t>(n);
  }
  return true;
}

std::string describe(int status) {
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "signal " + std::to_string(WTERMSIG(status));
  return "status " + std::to_string(status);
}

// The launcher's exit status for the program's wait status: the same code, or 128 + signal as a shell says.
int exit_code(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

// How waiting for Xvnc's display number went.
enum class DisplayWait { kReady, kXvncExited, kTimedOut, kStopped };

// Reads Xvnc's display number ("N\n") from `pipe_fd`, watching `signal_fd` for a stop, until `deadline`.
DisplayWait wait_for_display(int pipe_fd, int signal_fd, steady_clock::time_point deadline, int& display,
                             bool& stop_requested) {
  std::string text;
  for (;;) {
    if (stop_requested) return DisplayWait::kStopped;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - steady_clock::now());
    if (left.count() <= 0) return DisplayWait::kTimedOut;
    pollfd watch[2] = {{pipe_fd, POLLIN, 0}, {signal_fd, POLLIN, 0}};
    if (::poll(watch, 2, static_cast<int>(left.count())) < 0 && errno != EINTR) return DisplayWait::kTimedOut;
    if ((watch[1].revents & POLLIN) != 0) drain_signals(signal_fd, stop_requested);
    if ((watch[0].revents & (POLLIN | POLLHUP)) == 0) continue;
    char buffer[32];
    const ssize_t n = ::read(pipe_fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return DisplayWait::kXvncExited;  // its only writer is gone
    text.append(buffer, static_cast<std::size_t>(n));
    if (const std::size_t newline = text.find('\n'); newline != std::string::npos) {
      try {
        std::size_t used = 0;
        display = std::stoi(text.substr(0, newline), &used);
        if (used == newline && display >= 0 && display < 65536) return DisplayWait::kReady;
      } catch (const std::exception&) {
      }
      say("Xvnc wrote '" + text.substr(0, newline) + "' instead of a display number");
      return DisplayWait::kTimedOut;
    }
    if (text.size() > 16) {
      say("Xvnc wrote no display number");
      return DisplayWait::kTimedOut;
    }
  }
}

std::vector<std::string> environment_strings() {
  std::vector<std::string> out;
  for (char** entry = environ; entry != nullptr && *entry != nullptr; ++entry) out.emplace_back(*entry);
  return out;
}

}  // namespace

int run_session(const SessionOptions& options) {
  // Signals first: a stop that comes while Xvnc starts must still lead to the clean-up.
  sigset_t watched;
  sigemptyset(&watched);
  for (const int sig : {SIGCHLD, SIGTERM, SIGINT, SIGHUP}) sigaddset(&watched, sig);
  ::sigprocmask(SIG_BLOCK, &watched, nullptr);
  ::signal(SIGPIPE, SIG_IGN);  // a manager that has gone makes the ready write fail, not kill us

  // The manager's pipe is for us alone: neither Xvnc nor the program inherits it. Checked before any descriptor
  // of ours is made, which would otherwise take a closed fd's number and pass for it.
  Fd ready;
  if (options.ready_fd >= 0) {
    if (::fcntl(options.ready_fd, F_SETFD, FD_CLOEXEC) != 0) {
      say("--ready-fd " + std::to_string(options.ready_fd) + " is not an open descriptor");
      return 2;
    }
    ready.fd = options.ready_fd;
  }

  const Fd signals(::signalfd(-1, &watched, SFD_CLOEXEC | SFD_NONBLOCK));
  if (signals.fd < 0) {
    say(std::string("signalfd: ") + std::strerror(errno));
    return 1;
  }
  bool stop_requested = false;

  // Absolute, so that the program finds it whatever directory it moves to.
  std::error_code ec;
  const std::string xauthority = std::filesystem::absolute(options.xauthority, ec).string();
  Leftovers leftovers(xauthority, options.rfb_socket);
  try {
    write_xauthority(xauthority, random_cookie());
  } catch (const std::exception& error) {
    say(error.what());
    return 1;
  }

  // Xvnc, its output in ./xvnc.log, its display number on a pipe.
  SessionOptions xvnc_options = options;
  xvnc_options.xauthority = xauthority;
  pid_t xvnc = -1;
  Fd display_pipe;
  {
    const Fd log(::open(kXvncLog, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600));
    if (log.fd < 0) {
      say(std::string("cannot open ") + kXvncLog + ": " + std::strerror(errno));
      return 1;
    }
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
      say(std::string("pipe: ") + std::strerror(errno));
      return 1;
    }
    display_pipe.fd = fds[0];
    const Fd display_write(fds[1]);
    ChildSpec spec;
    spec.argv = xvnc_arguments(xvnc_options, display_write.fd);
    spec.env = environment_strings();
    spec.output_fd = log.fd;
    spec.pass_fd = display_write.fd;
    spec.death_signal = SIGTERM;  // Xvnc removes its own files on SIGTERM
    try {
      xvnc = spawn_child(spec);
    } catch (const std::exception& error) {
      say(error.what());
      return 1;
    }
  }

  int display = -1;
  switch (wait_for_display(display_pipe.fd, signals.fd, steady_clock::now() + kXvncStartTimeout, display,
                           stop_requested)) {
    case DisplayWait::kReady:
      break;
    case DisplayWait::kXvncExited: {
      // It closed the pipe, so it is exiting: reap it (and only if it lingers, stop it).
      int status = 0;
      if (!wait_child_until(xvnc, steady_clock::now() + kXvncGrace, signals.fd, status, stop_requested)) {
        status = stop_child(xvnc, kXvncGrace, signals.fd, stop_requested);
      }
      say("Xvnc ended before its display was ready (" + describe(status) + "); see " + kXvncLog);
      return 1;
    }
    case DisplayWait::kTimedOut:
      say("Xvnc did not name its display within " + std::to_string(kXvncStartTimeout.count()) + " s; see " +
          kXvncLog);
      stop_child(xvnc, kXvncGrace, signals.fd, stop_requested);
      return 1;
    case DisplayWait::kStopped:
      stop_child(xvnc, kXvncGrace, signals.fd, stop_requested);
      return 0;
  }
  display_pipe.reset();
  leftovers.display = display;

  // Xvnc that exited by itself removed its display's files; only one that was killed leaves them (and then the
  // number may be another server's by the time we look, so a clean exit is not looked after).
  const auto stop_xvnc = [&] {
    const int status = stop_child(xvnc, kXvncGrace, signals.fd, stop_requested);
    if (WIFEXITED(status)) leftovers.display = -1;
  };

  // The program on that display, with the cookie; its output goes where ours goes.
  // Where the session is, for whoever reads our output; before the program starts, which shares our stdout and
  // would otherwise print ahead of it.
  std::printf("display :%d\n", display);
  std::fflush(stdout);
  pid_t program = -1;
  {
    ChildSpec spec;
    spec.argv = options.program;
    spec.env = program_environment(environment_strings(), display, xauthority);
    spec.search_path = true;
    spec.death_signal = SIGKILL;  // with no launcher, nobody would stop it
    try {
      program = spawn_child(spec);
    } catch (const std::exception& error) {
      say(error.what());
      stop_xvnc();
      return 1;
    }
  }

  if (ready.fd >= 0) {
    const std::string lines = contract::ready_unix_line(options.rfb_socket) + contract::x11_display_line(display);
    if (!write_all(ready.fd, lines)) say(std::string("cannot write the ready lines: ") + std::strerror(errno));
    ready.reset();
  }

  // Live as long as both.
  for (;;) {
    // The manager signals the whole group: a stop that comes with the program's exit is still a stop (exit 0).
    drain_signals(signals.fd, stop_requested);
    int status = 0;
    const bool program_ended = ::waitpid(program, &status, WNOHANG) == program;
    if (stop_requested) {
      if (!program_ended) stop_child(program, kProgramGrace, signals.fd, stop_requested);
      stop_xvnc();
      return 0;
    }
    if (program_ended) {
      stop_xvnc();
      return exit_code(status);
    }
    if (::waitpid(xvnc, &status, WNOHANG) == xvnc) {
      say("Xvnc ended (" + describe(status) + "); stopping " + options.program.front() + "; see " + kXvncLog);
      if (WIFEXITED(status)) leftovers.display = -1;
      stop_child(program, kProgramGrace, signals.fd, stop_requested);
      return 1;
    }
    pollfd watch{signals.fd, POLLIN, 0};
    ::poll(&watch, 1, -1);
    drain_signals(signals.fd, stop_requested);
  }
}

}  // namespace rfbsim::x11
