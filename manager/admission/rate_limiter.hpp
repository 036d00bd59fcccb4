// SPDX-License-Identifier: GPL-2.0-or-later
// RateLimiter: a token bucket per client address, for /start and WebSocket upgrades. Pure: time is passed in.
//
// Each address may spend `burst` requests at once and then `per_minute` a minute, refilled evenly. A refused
// request learns how long until the next token (Retry-After). Memory is bounded: a bucket that has refilled
// completely is the same as no bucket and is dropped when the table is swept, and when the table is full of
// busy addresses the oldest-touched bucket makes room (an attacker with many addresses gains a fresh burst
// per address, which the connection caps and slots bound anyway).
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <string>

namespace rfbsim::manager {

/// The rate an address may keep up. per_minute 0 switches the limit off.
struct RateLimit {
  double per_minute = 0;  ///< sustained requests per minute
  double burst = 1;       ///< requests at once (at least 1)
};

class RateLimiter {
 public:
  using Clock = std::chrono::steady_clock;

  /// A decision on one request.
  struct Decision {
    bool allowed = true;
    std::chrono::seconds retry_after{0};  ///< refused: whole seconds until a token is back (at least 1)
  };

  explicit RateLimiter(RateLimit limit, std::size_t max_addresses = 65536);

  /// Takes one token of `address`'s bucket at `now`, if it has one.
  Decision take(const std::string& address, Clock::time_point now);

  /// Buckets kept now (for tests and the soak's memory check).
  [[nodiscard]] std::size_t tracked() const { return buckets_.size(); }
  [[nodiscard]] bool enabled() const { return limit_.per_minute > 0; }

 private:
  struct Bucket {
    double tokens = 0;
    Clock::time_point updated;
  };
  void refill(Bucket& bucket, Clock::time_point now) const;
  void sweep(Clock::time_point now);

  RateLimit limit_;
  std::size_t max_addresses_;
  std::map<std::string, Bucket> buckets_;
  Clock::time_point last_sweep_{};
};

}  // namespace rfbsim::manager
