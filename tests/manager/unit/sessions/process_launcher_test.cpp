// SPDX-License-Identifier: GPL-2.0-or-later
// The launcher starts real child processes on its own thread, in order, and says why a start failed.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "sessions/process_launcher.hpp"
#include "reap_child.hpp"
#include "scratch_dir.hpp"

using rfbsim::manager::LaunchJob;
using rfbsim::manager::LaunchResult;
using rfbsim::manager::ProcessLauncher;
using rfbsim::manager::run_launch;
using rfbsim::test::reap_child;
using rfbsim::test::ScratchDir;

namespace {

// A job that makes `folder` and runs `script` with /bin/sh there.
LaunchJob shell_job(const std::string& folder, const std::string& script) {
  LaunchJob job;
  job.folder = folder;
  job.spec.program = "/bin/sh";
  job.spec.args = {"-c", script};
  job.spec.working_dir = folder;
  job.spec.log_file = folder + "/session.log";
  job.spec.ready_pipe = false;
  return job;
}

}  // namespace

TEST_CASE("a launch makes the session's folder and starts its program off the caller's thread") {
  ScratchDir dir;
  const std::string folder = dir.path("sessions/1-p1");
  REQUIRE_FALSE(std::filesystem::exists(folder));
  std::promise<std::pair<LaunchResult, std::thread::id>> got;
  {
    ProcessLauncher launcher;
    launcher.launch(shell_job(folder, "exit 7"), [&got](LaunchResult result) {
      got.set_value({std::move(result), std::this_thread::get_id()});
    });
    auto future = got.get_future();
    REQUIRE(future.wait_for(std::chrono::seconds(30)) == std::future_status::ready);
    auto [result, thread] = future.get();
    CHECK(thread != std::this_thread::get_id());
    CHECK(result.error.empty());
    REQUIRE(result.process.pid > 1);
    CHECK(std::filesystem::is_directory(folder));
    const int status = reap_child(result.process.pid);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 7);
  }
}

TEST_CASE("a launch that cannot start names the cause and leaves no process") {
  ScratchDir dir;
  LaunchJob job = shell_job(dir.path("s"), "true");
  job.spec.program = dir.path("no-such-program");
  const LaunchResult result = run_launch(job);
  CHECK(result.process.pid == -1);
  CHECK(result.error.find("cannot run " + dir.path("no-such-program")) == 0);
  CHECK(result.error.find("No such file or directory") != std::string::npos);
  CHECK(::waitpid(-1, nullptr, WNOHANG) == -1);  // the failed child was reaped: none is left to us
  CHECK(errno == ECHILD);
}

TEST_CASE("a launch whose folder cannot be made fails with the reason, not an exception") {
  ScratchDir dir;
  std::filesystem::create_directories(dir.path("file-parent"));
  { std::ofstream(dir.path("file-parent/blocker")) << "x"; }
  const LaunchResult result = run_launch(shell_job(dir.path("file-parent/blocker/s"), "true"));
  CHECK(result.process.pid == -1);
  CHECK_FALSE(result.error.empty());
}

TEST_CASE("launches run one after another, in the order they were queued") {
  ScratchDir dir;
  std::mutex mutex;
  std::vector<int> order;
  std::vector<pid_t> started;
  std::promise<void> all_done;
  {
    ProcessLauncher launcher;
    for (int i = 0; i < 3; ++i) {
      launcher.launch(shell_job(dir.path("s" + std::to_string(i)), "exit 0"), [&, i](LaunchResult result) {
        std::lock_guard<std::mutex> lock(mutex);
        order.push_back(i);
        started.push_back(result.process.pid);
        if (order.size() == 3) all_done.set_value();
      });
    }
    REQUIRE(all_done.get_future().wait_for(std::chrono::seconds(30)) == std::future_status::ready);
  }
  CHECK(order == std::vector<int>{0, 1, 2});
  for (const pid_t pid : started) {
    REQUIRE(pid > 1);
    reap_child(pid);
  }
}
