// SPDX-License-Identifier: GPL-2.0-or-later
// LogLimiter on a fake clock: cut and cleaned text, repeats dropped, one line a second per kind with the
// count of what was suppressed, kinds independent.
#include <catch2/catch.hpp>

#include <string>

#include "ros/bridge/log_limiter.hpp"

using rfbsim::ros::LogLimiter;
using std::chrono::milliseconds;

TEST_CASE("the log limiter cuts, cleans, drops repeats and rate-limits each kind") {
  LogLimiter::Clock::time_point now{};
  LogLimiter limiter([&now] { return now; });

  // A megabyte of hostile text becomes 200 printable characters and "...".
  const auto first = limiter.admit("server", std::string(1 << 20, 'x') + "\x1b[2J");
  REQUIRE(first);
  CHECK(*first == std::string(LogLimiter::kMaxChars, 'x') + "...");
  CHECK(*limiter.admit("other", "bell\a and escape\x1b") == "bell? and escape?");

  // Within the second: dropped and counted; an exact repeat is dropped even later, and not counted.
  for (int n = 0; n < 5; ++n) CHECK_FALSE(limiter.admit("server", "line " + std::to_string(n)));
  now += milliseconds(999);
  CHECK_FALSE(limiter.admit("server", "line 5"));
  now += milliseconds(1);
  CHECK(*limiter.admit("server", "line 6") == "(6 more suppressed) line 6");
  now += milliseconds(5000);
  CHECK_FALSE(limiter.admit("server", "line 6"));
  CHECK(*limiter.admit("server", "line 7") == "line 7");
  CHECK(*limiter.admit("fail", "line 7") == "line 7");  // another kind has its own budget
}
