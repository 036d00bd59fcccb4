// SPDX-License-Identifier: GPL-2.0-or-later
// ChildProcess: fork, a process group of its own, execvp; stopped group-wide.
#include "child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace rfbsim::test {

namespace {

// This process's environment with `extra` (NAME=value) added, replacing a variable of the same name.
std::vector<std::string> merged_environment(const std::vector<std::string>& extra) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const std::string name = entry.substr(0, entry.find('=') + 1);
    bool replaced = false;
    for (const auto& x : extra) replaced = replaced || x.rfind(name, 0) == 0;
    if (!replaced) env.push_back(entry);
  }
  env.insert(env.end(), extra.begin(), extra.end());
  return env;
}

// Forks and execs `spec` with stdout and stderr on `output_fd`. The child leads a new process group, so that
// stopping it also stops anything it started.
pid_t spawn(const ChildSpec& spec, int output_fd) {
  std::vector<std::string> argv_text = spec.argv;
  std::vector<char*> argv;
  for (auto& arg : argv_text) argv.push_back(arg.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text = merged_environment(spec.extra_env);
  std::vector<char*> env;
  for (auto& entry : env_text) env.push_back(entry.data());
  env.push_back(nullptr);

  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    // Only async-signal-safe calls until exec.
    ::setpgid(0, 0);
    ::dup2(output_fd, STDOUT_FILENO);
    ::dup2(output_fd, STDERR_FILENO);
    if (spec.pass_fd >= 0) ::fcntl(spec.pass_fd, F_SETFD, 0);
    ::execvpe(argv[0], argv.data(), env.data());
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also from here, so that the group exists before anyone signals it
  return pid;
}

// Waits for `pid` until `deadline`; true with its status once it has exited.
bool wait_until(pid_t pid, std::chrono::steady_clock::time_point deadline, int& status) {
  while (true) {
    const pid_t got = ::waitpid(pid, &status, WNOHANG);
    if (got == pid) return true;
    if (got < 0 && errno != EINTR) return true;  // not ours any more: nothing to wait for
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

ChildProcess::ChildProcess(const ChildSpec& spec) {
  const std::string log = spec.log_path.empty() ? "/dev/null" : spec.log_path;
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + log + ": " + std::strerror(errno));
  try {
    pid_ = spawn(spec, fd);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

ChildProcess::~ChildProcess() {
  if (pid_ <= 0 || reaped_) return;
  ::kill(-pid_, SIGTERM);
  int status = 0;
  if (!wait_until(pid_, std::chrono::steady_clock::now() + std::chrono::seconds(3), status)) {
    ::kill(-pid_, SIGKILL);
    wait_until(pid_, std::chrono::steady_clock::now() + std::chrono::seconds(10), status);
  }
}

bool ChildProcess::running() {
  if (reaped_) return false;
  int status = 0;
  const pid_t got = ::waitpid(pid_, &status, WNOHANG);
  if (got == pid_) reaped_ = true;
  return !reaped_;
}

std::string run_child(const ChildSpec& spec, int& status, std::chrono::milliseconds timeout) {
  int output[2];
  if (::pipe2(output, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  pid_t pid = -1;
  try {
    pid = spawn(spec, output[1]);
  } catch (...) {
    ::close(output[0]);
    ::close(output[1]);
    throw;
  }
  ::close(output[1]);
  // Read to the end of the output (every writer closed it) or the deadline.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string text;
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd pfd{output[0], POLLIN, 0};
    if (left.count() <= 0 || ::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) break;
    char buffer[4096];
    const auto n = ::read(output[0], buffer, sizeof buffer);
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(output[0]);
  status = -1;
  if (!wait_until(pid, std::chrono::steady_clock::now() + std::chrono::seconds(1), status)) {
    ::kill(-pid, SIGKILL);
    int ignored = 0;
    wait_until(pid, std::chrono::steady_clock::now() + std::chrono::seconds(10), ignored);
    status = -1;
  }
  return text;
}

}  // namespace rfbsim::test
