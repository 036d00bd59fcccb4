// SPDX-License-Identifier: GPL-2.0-or-later
// ReconnectBackoff with chosen random draws: doubling from 0.5 s to the maximum, +-25 % jitter, reset.
#include <catch2/catch.hpp>

#include "ros/bridge/reconnect_backoff.hpp"

using rfbsim::ros::ReconnectBackoff;
using std::chrono::milliseconds;

TEST_CASE("reconnect waits double to the maximum, spread by +-25 %") {
  ReconnectBackoff backoff(milliseconds(3000));
  CHECK(backoff.next(0.5) == milliseconds(500));    // no jitter at the middle draw
  CHECK(backoff.next(0.0) == milliseconds(750));    // 1000 - 25 %
  CHECK(backoff.next(1.0) == milliseconds(2500));   // 2000 + 25 %
  CHECK(backoff.next(0.5) == milliseconds(3000));   // capped
  CHECK(backoff.next(0.25) == milliseconds(2625));  // 3000 - 12.5 %
  backoff.reset();
  CHECK(backoff.next(0.5) == milliseconds(500));

  // A maximum below the first wait does not shrink it.
  ReconnectBackoff tiny(milliseconds(10));
  tiny.next(0.5);
  CHECK(tiny.next(0.5) == milliseconds(500));
}
