// SPDX-License-Identifier: GPL-2.0-or-later
// An abusive client of sim_manager for bench_manager --abuse: from one source address it holds many idle
// half-open connections (connected, half an HTTP request sent, then silence) and hammers /start with made-up
// uids, each on threads of its own, until stopped. Plain sockets; it never reads sim_manager's code.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace rfbsim::bench {

/// What the abuser does; every field but port has the default the bench uses.
struct AbuserOptions {
  int port = 0;                         ///< sim_manager's port on 127.0.0.1
  std::string from = "127.0.0.2";       ///< source address of every connection (Linux routes 127/8 to loopback)
  int half_open = 2000;                 ///< idle half-open connections to hold
  /// A held connection that the manager closed (or that failed) is opened again after this long, so the
  /// abuser keeps pressing on the connection caps like a real one would.
  std::chrono::milliseconds reopen_after{1000};
  std::chrono::milliseconds connect_timeout{5000};  ///< a connect still pending this long is dropped and retried
  std::string scenario = "warehouse";   ///< the storm's links ask for it
  int storm_per_second = 0;             ///< /start requests per second at most; 0: one after the other, no pause
};

/// What the abuser did so far; a snapshot.
struct AbuserCounts {
  std::uint64_t connects = 0;          ///< half-open connections established
  std::uint64_t connect_errors = 0;    ///< connects that failed or timed out
  std::uint64_t closed_by_server = 0;  ///< established half-open connections the manager closed
  std::uint64_t open_now = 0;          ///< established and not yet closed, now
  std::uint64_t open_peak = 0;         ///< the most at once
  std::uint64_t storm_requests = 0;    ///< /start requests sent (or tried)
  /// Storm answers by HTTP status; -1 counts requests that got no answer (closed at accept, refused, timeout).
  std::map<int, std::uint64_t> storm_status;
};

/// Starts both kinds of abuse on construction; stop() or the destructor ends them and closes every socket.
class Abuser {
 public:
  /// Starts the threads; throws std::invalid_argument when options.from is not an IPv4 address.
  explicit Abuser(AbuserOptions options);
  /// Calls stop().
  ~Abuser();
  Abuser(const Abuser&) = delete;
  Abuser& operator=(const Abuser&) = delete;

  /// Stops and joins both threads (within about a second), closing every socket; idempotent.
  void stop();
  /// A snapshot of the counters (any thread).
  [[nodiscard]] AbuserCounts counts() const;

 private:
  void hold_half_open();  // the half-open thread's loop (epoll)
  void storm();           // the /start thread's loop (blocking sockets)

  AbuserOptions options_;
  std::uint32_t from_ = 0;  // options_.from, network byte order
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> connects_{0}, connect_errors_{0}, closed_by_server_{0}, open_now_{0}, open_peak_{0};
  std::atomic<std::uint64_t> storm_requests_{0};
  mutable std::mutex status_mutex_;
  std::map<int, std::uint64_t> storm_status_;  // under status_mutex_
  std::thread half_open_thread_;
  std::thread storm_thread_;
};

}  // namespace rfbsim::bench
