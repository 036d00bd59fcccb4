// SPDX-License-Identifier: GPL-2.0-or-later
// PipedSim: fork, the pipe as descriptor 3, execve with an extended environment, waitpid.
#include "piped_sim.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>
#include <thread>

extern char** environ;

namespace rfbsim::test {

PipedSim::PipedSim(const std::string& program, std::vector<std::string> args,
                   const std::vector<std::pair<std::string, std::string>>& env, const std::filesystem::path& log) {
  args.insert(args.begin(), program);
  args.insert(args.end(), {"--ready-fd", "3"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The environment is built before the fork: the child only calls async-signal-safe functions.
  std::vector<std::string> env_strings;
  for (const auto& [name, value] : env) env_strings.push_back(name + "=" + value);
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  for (char** e = environ; *e != nullptr; ++e) envp.push_back(*e);
  envp.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (log_fd < 0) throw std::runtime_error("cannot open " + log.string());
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    ::dup2(fds[1], 3);  // dup2 clears close-on-exec on the copy
    ::execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  ::close(log_fd);
  ::close(fds[1]);
  pipe_fd_ = fds[0];
}

PipedSim::~PipedSim() {
  if (!reaped_) stop(SIGKILL, std::chrono::seconds(5));
  if (pipe_fd_ >= 0) ::close(pipe_fd_);
}

bool PipedSim::read_some(std::chrono::milliseconds timeout) {
  pollfd pfd{pipe_fd_, POLLIN, 0};
  if (::poll(&pfd, 1, static_cast<int>(timeout.count())) <= 0) return false;
  char buffer[1024];
  const ssize_t n = ::read(pipe_fd_, buffer, sizeof buffer);
  if (n <= 0) return false;
  partial_.append(buffer, static_cast<std::size_t>(n));
  for (std::size_t nl = partial_.find('\n'); nl != std::string::npos; nl = partial_.find('\n')) {
    lines_.push_back(partial_.substr(0, nl + 1));
    partial_.erase(0, nl + 1);
  }
  return true;
}

std::string PipedSim::await_line(const std::string& prefix, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t checked = 0;
  for (;;) {
    for (; checked < lines_.size(); ++checked) {
      if (lines_[checked].rfind(prefix, 0) == 0) return lines_[checked].substr(0, lines_[checked].size() - 1);
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || !read_some(left)) return "";
  }
}

int PipedSim::stop(int signal, std::chrono::milliseconds timeout) {
  if (reaped_) return -1;
  ::kill(pid_, signal);
  // The pipe ends when the process has gone; keep what it said last.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (!read_some(left)) break;
  }
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, &status, 0);
  reaped_ = true;
  return -1;
}

}  // namespace rfbsim::test
