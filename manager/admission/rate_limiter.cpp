// SPDX-License-Identifier: GPL-2.0-or-later
// RateLimiter: token buckets per address.
#include "admission/rate_limiter.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::manager {

namespace {
// How often full buckets are dropped: often enough to keep memory flat, rarely enough to cost nothing.
constexpr auto kSweepInterval = std::chrono::seconds(10);
// Refills add up in floating point: a token due at exactly this instant must not be missed by rounding.
constexpr double kTokenEpsilon = 1e-9;
}  // namespace

RateLimiter::RateLimiter(RateLimit limit, std::size_t max_addresses)
    : limit_(limit), max_addresses_(std::max<std::size_t>(1, max_addresses)) {
  limit_.burst = std::max(1.0, limit_.burst);
}

void RateLimiter::refill(Bucket& bucket, Clock::time_point now) const {
  const double minutes = std::chrono::duration<double>(now - bucket.updated).count() / 60.0;
  if (minutes > 0) bucket.tokens = std::min(limit_.burst, bucket.tokens + minutes * limit_.per_minute);
  bucket.updated = std::max(bucket.updated, now);
}

void RateLimiter::sweep(Clock::time_point now) {
  for (auto it = buckets_.begin(); it != buckets_.end();) {
    refill(it->second, now);
    it = it->second.tokens >= limit_.burst ? buckets_.erase(it) : std::next(it);
  }
  last_sweep_ = now;
}

RateLimiter::Decision RateLimiter::take(const std::string& address, Clock::time_point now) {
  if (!enabled()) return {};
  if (now - last_sweep_ >= kSweepInterval) sweep(now);

  auto it = buckets_.find(address);
  if (it == buckets_.end()) {
    if (buckets_.size() >= max_addresses_) {
      sweep(now);
      if (buckets_.size() >= max_addresses_) {
        // Still full of busy addresses: forget the one left alone longest.
        auto oldest = std::min_element(buckets_.begin(), buckets_.end(), [](const auto& a, const auto& b) {
          return a.second.updated < b.second.updated;
        });
        buckets_.erase(oldest);
      }
    }
    it = buckets_.emplace(address, Bucket{limit_.burst, now}).first;
  }
  Bucket& bucket = it->second;
  refill(bucket, now);
  if (bucket.tokens >= 1 - kTokenEpsilon) {
    bucket.tokens = std::max(0.0, bucket.tokens - 1);
    return {};
  }
  const double seconds_to_token = (1 - bucket.tokens) * 60.0 / limit_.per_minute;
  return {false, std::chrono::seconds(std::max<long long>(1, static_cast<long long>(std::ceil(seconds_to_token))))};
}

}  // namespace rfbsim::manager
