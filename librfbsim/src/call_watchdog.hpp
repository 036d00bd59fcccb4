// SPDX-License-Identifier: GPL-2.0-or-later
// CallWatchdog: bounds how long one blocking call on behalf of one socket may take.
//
// libvncserver reads a client message and writes an update with blocking loops of its own: a client that
// sends a message one byte at a time, or stops reading, keeps the server's only network thread inside that
// loop while every other client waits. The network thread arms the watchdog with the client's socket
// before each such call; if the call is still running at the deadline, the watchdog shuts the socket down
// from its own thread, the blocked read or write fails at once, and libvncserver drops that client.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace rfbsim::detail {

class CallWatchdog {
 public:
  using Clock = std::chrono::steady_clock;

  CallWatchdog();
  ~CallWatchdog();
  CallWatchdog(const CallWatchdog&) = delete;
  CallWatchdog& operator=(const CallWatchdog&) = delete;

  /// Starts watching one call made for socket `fd`; at `deadline` the socket is shut down (both ways).
  /// `fd` must stay open until disarm() or forget(fd) returns: pass a descriptor you own (a dup).
  void arm(int fd, Clock::time_point deadline);
  /// The call has returned in time (or not): stop watching.
  void disarm();
  /// Stops watching if the watched socket is `fd`; call before closing it.
  void forget(int fd);
  /// How many calls were cut off since construction.
  [[nodiscard]] std::uint64_t fired() const;

 private:
  void run();

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  int fd_ = -1;  // -1 = nothing watched
  Clock::time_point deadline_{};
  std::uint64_t generation_ = 0;  // counts arm() calls, so a stale deadline is never applied to a new call
  std::uint64_t fired_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace rfbsim::detail
