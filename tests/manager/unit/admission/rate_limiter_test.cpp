// SPDX-License-Identifier: GPL-2.0-or-later
// RateLimiter: token buckets per address with a fake clock.
#include "admission/rate_limiter.hpp"

#include <catch2/catch.hpp>
#include <string>

using rfbsim::manager::RateLimit;
using rfbsim::manager::RateLimiter;
using namespace std::chrono_literals;

namespace {
const RateLimiter::Clock::time_point t0 = RateLimiter::Clock::time_point{} + 1h;
}

TEST_CASE("an address gets its burst at once, then one request per refill interval") {
  RateLimiter limiter({6, 3});  // 6 a minute: one token every 10 s
  CHECK(limiter.take("a", t0).allowed);
  CHECK(limiter.take("a", t0).allowed);
  CHECK(limiter.take("a", t0).allowed);
  const auto refused = limiter.take("a", t0);
  CHECK_FALSE(refused.allowed);
  CHECK(refused.retry_after == 10s);
  CHECK_FALSE(limiter.take("a", t0 + 9s).allowed);
  CHECK(limiter.take("a", t0 + 10s).allowed);
  CHECK_FALSE(limiter.take("a", t0 + 10s).allowed);
}

TEST_CASE("each address has its own bucket") {
  RateLimiter limiter({60, 1});
  CHECK(limiter.take("a", t0).allowed);
  CHECK_FALSE(limiter.take("a", t0).allowed);
  CHECK(limiter.take("b", t0).allowed);
  CHECK(limiter.tracked() == 2);
}

TEST_CASE("Retry-After rounds up and is at least a second") {
  RateLimiter limiter({120, 1});  // a token every 0.5 s
  CHECK(limiter.take("a", t0).allowed);
  CHECK(limiter.take("a", t0).retry_after == 1s);
  RateLimiter slow({1, 1});  // one a minute
  CHECK(slow.take("a", t0).allowed);
  CHECK(slow.take("a", t0 + 15s).retry_after == 45s);
}

TEST_CASE("a refilled bucket never holds more than the burst") {
  RateLimiter limiter({60, 2});
  CHECK(limiter.take("a", t0).allowed);
  // An hour later: still only two at once.
  CHECK(limiter.take("a", t0 + 1h).allowed);
  CHECK(limiter.take("a", t0 + 1h).allowed);
  CHECK_FALSE(limiter.take("a", t0 + 1h).allowed);
}

TEST_CASE("per_minute 0 switches the limit off") {
  RateLimiter limiter({0, 1});
  CHECK_FALSE(limiter.enabled());
  for (int i = 0; i < 1000; ++i) REQUIRE(limiter.take("a", t0).allowed);
  CHECK(limiter.tracked() == 0);
}

TEST_CASE("memory stays bounded: full buckets are swept and a full table drops the stalest") {
  RateLimiter limiter({60, 5}, 100);
  for (int i = 0; i < 1000; ++i) limiter.take("addr" + std::to_string(i), t0 + std::chrono::milliseconds(i));
  CHECK(limiter.tracked() <= 100);
  // A minute later every bucket has refilled: the next sweep drops them all but the new one.
  limiter.take("late", t0 + 2min);
  CHECK(limiter.tracked() == 1);
}
