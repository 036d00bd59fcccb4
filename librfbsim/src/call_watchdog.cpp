// SPDX-License-Identifier: GPL-2.0-or-later
#include "call_watchdog.hpp"

#include <sys/socket.h>

namespace rfbsim::detail {

CallWatchdog::CallWatchdog() : thread_([this] { run(); }) {}

CallWatchdog::~CallWatchdog() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_one();
  thread_.join();
}

void CallWatchdog::arm(int fd, Clock::time_point deadline) {
  {
    const std::lock_guard lock(mutex_);
    fd_ = fd;
    deadline_ = deadline;
    ++generation_;
  }
  changed_.notify_one();
}

void CallWatchdog::disarm() {
  const std::lock_guard lock(mutex_);
  fd_ = -1;
}

void CallWatchdog::forget(int fd) {
  const std::lock_guard lock(mutex_);
  if (fd_ == fd) fd_ = -1;
}

std::uint64_t CallWatchdog::fired() const {
  const std::lock_guard lock(mutex_);
  return fired_;
}

void CallWatchdog::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (fd_ < 0) {
      changed_.wait(lock);
      continue;
    }
    const std::uint64_t watched = generation_;
    const auto deadline = deadline_;
    // Wakes early only for stop or a new arm(); a disarm() is noticed at the deadline, which is cheap.
    changed_.wait_until(lock, deadline, [&] { return stopping_ || generation_ != watched; });
    if (stopping_ || generation_ != watched || fd_ < 0) continue;
    // Still the same call, past its deadline. The descriptor cannot be closed meanwhile: closing it
    // requires forget() or disarm() first, which take this lock.
    ::shutdown(fd_, SHUT_RDWR);
    fd_ = -1;
    ++fired_;
  }
}

}  // namespace rfbsim::detail
