// SPDX-License-Identifier: GPL-2.0-or-later
// ProcessLauncher: session starts in order, off the I/O thread.
#include "sessions/process_launcher.hpp"

#include <filesystem>

namespace rfbsim::manager {

LaunchResult run_launch(const LaunchJob& job) {
  LaunchResult result;
  try {
    if (!job.folder.empty()) std::filesystem::create_directories(job.folder);
    result.process = spawn_session_process(job.spec);
  } catch (const std::exception& failure) {
    result.process = SpawnedProcess{};
    result.error = failure.what();
  }
  return result;
}

ProcessLauncher::ProcessLauncher() : thread_([this] { run(); }) {}

ProcessLauncher::~ProcessLauncher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void ProcessLauncher::launch(LaunchJob job, Done done) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back({std::move(job), std::move(done)});
  }
  wake_.notify_one();
}

void ProcessLauncher::run() {
  for (;;) {
    Queued next;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
      // Stopping: a start not yet made is dropped, since no one is left to watch over its process.
      if (stopping_) return;
      next = std::move(jobs_.front());
      jobs_.pop_front();
    }
    LaunchResult result = run_launch(next.job);
    if (next.done) next.done(std::move(result));
  }
}

}  // namespace rfbsim::manager
