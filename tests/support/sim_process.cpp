// SPDX-License-Identifier: GPL-2.0-or-later
// SimProcess: fork + execv, a stdout pipe, SIGTERM and waitpid.
#include "sim_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cstdlib>
#include <regex>
#include <stdexcept>

namespace rfbsim::test {

std::string sim_rfb_path() {
  const char* from_env = std::getenv("RFBSIM_SIM_RFB");
#ifdef RFBSIM_SIM_RFB_DEFAULT
  return from_env != nullptr ? from_env : RFBSIM_SIM_RFB_DEFAULT;
#else
  return from_env != nullptr ? from_env : "sim_rfb";
#endif
}

namespace {

// A child running `program` with `args` (no shell); its stdout, and stderr too when asked, go to a pipe; else its
// stderr is appended to `stderr_path` where one is given.
struct Spawned {
  pid_t pid = -1;
  int output_fd = -1;  // the pipe's read end, owned by the caller
};

Spawned spawn(const std::string& program, const std::vector<std::string>& args, bool with_stderr,
              const std::string& stderr_path = {}) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  const int stderr_fd =
      stderr_path.empty() ? -1 : ::open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (!stderr_path.empty() && stderr_fd < 0) throw std::runtime_error("cannot open " + stderr_path);
  std::vector<std::string> argv_strings{program};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    // A test that dies on a signal never runs its destructors: its child must not outlive it and hold ctest's
    // output pipe open until the timeout.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    if (with_stderr) ::dup2(pipe_fds[1], STDERR_FILENO);
    if (stderr_fd >= 0) ::dup2(stderr_fd, STDERR_FILENO);
    ::execv(program.c_str(), argv.data());
    _exit(127);
  }
  ::close(pipe_fds[1]);
  if (stderr_fd >= 0) ::close(stderr_fd);
  return {pid, pipe_fds[0]};
}

}  // namespace

ExitResult run_to_exit(const std::string& program, const std::vector<std::string>& args,
                       std::chrono::milliseconds timeout) {
  const Spawned child = spawn(program, args, true);
  const pid_t pid = child.pid;
  const int output_fd = child.output_fd;
  ExitResult result;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  // Read until end of file (the child exited and closed its end) or the deadline.
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd pfd{output_fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) {
      ::kill(pid, SIGKILL);
      break;
    }
    char buffer[512];
    const auto n = ::read(output_fd, buffer, sizeof buffer);
    if (n <= 0) break;
    result.output.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(output_fd);
  int status = 0;
  ::waitpid(pid, &status, 0);
  result.status = std::chrono::steady_clock::now() < deadline ? status : -1;
  return result;
}

SimProcess::SimProcess(const std::string& program, const std::vector<std::string>& args,
                       std::chrono::milliseconds timeout, const std::string& stderr_path) {
  const Spawned child = spawn(program, args, false, stderr_path);
  pid_ = child.pid;
  stdout_fd_ = child.output_fd;

  // Read stdout until the ready line names the URL.
  std::string output;
  const std::regex ready(R"(ready: (https?://[^:/\s]+:(\d+)/))");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::smatch match;
  while (!std::regex_search(output, match, ready)) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd pfd{stdout_fd_, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) {
      stop(SIGKILL);
      throw std::runtime_error("sim_rfb printed no ready line in time; output so far: " + output);
    }
    char buffer[512];
    const auto n = ::read(stdout_fd_, buffer, sizeof buffer);
    if (n <= 0) {
      stop(SIGKILL);
      throw std::runtime_error("sim_rfb exited before it was ready; output: " + output);
    }
    output.append(buffer, static_cast<std::size_t>(n));
  }
  url_ = match[1];
  port_ = std::stoi(match[2]);
}

SimProcess::~SimProcess() {
  if (!reaped_) stop(SIGKILL, std::chrono::seconds(5));
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
}

bool SimProcess::running() {
  if (reaped_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    reaped_ = true;
    return false;
  }
  return true;
}

int SimProcess::stop(int signal, std::chrono::milliseconds timeout) {
  if (reaped_ || pid_ <= 0) return -1;
  // A pidfd becomes readable when the process exits: wait on that instead of polling waitpid.
  const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, pid_, 0));
  ::kill(pid_, signal);
  if (pidfd >= 0) {
    pollfd pfd{pidfd, POLLIN, 0};
    ::poll(&pfd, 1, static_cast<int>(timeout.count()));
    ::close(pidfd);
  }
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    reaped_ = true;
    return status;
  }
  return -1;
}

}  // namespace rfbsim::test
