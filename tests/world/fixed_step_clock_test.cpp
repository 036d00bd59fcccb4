// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "world/fixed_step_clock.hpp"

using namespace std::chrono_literals;
using rfbsim::sim::FixedStepClock;

TEST_CASE("steps are whole multiples of dt and the remainder carries over") {
  FixedStepClock clock(10ms);
  CHECK(clock.advance(25ms) == 2);
  CHECK(clock.remainder() == 5ms);
  CHECK(clock.until_next_step() == 5ms);
  CHECK(clock.advance(4ms) == 0);
  CHECK(clock.advance(1ms) == 1);
  CHECK(clock.remainder() == 0ms);
}

TEST_CASE("frame rate does not change the number of steps") {
  FixedStepClock fast(std::chrono::nanoseconds(16'666'667)), slow(std::chrono::nanoseconds(16'666'667));
  int fast_steps = 0, slow_steps = 0;
  for (int i = 0; i < 120; ++i) fast_steps += fast.advance(std::chrono::nanoseconds(8'333'333));  // 120 fps
  for (int i = 0; i < 20; ++i) slow_steps += slow.advance(50ms);                                  // 20 fps
  CHECK(fast_steps == 59);  // 999,999,960 ns: just short of the 60th step
  CHECK(slow_steps == 59);  // 1 s exactly is 59.99999 steps of 16.666667 ms
}

TEST_CASE("a long stall is capped and counted - and negative time is ignored") {
  FixedStepClock clock(10ms, 5);
  CHECK(clock.advance(1s) == 5);
  CHECK(clock.dropped_steps() == 95);
  CHECK(clock.advance(-5ms) == 0);
  CHECK_THROWS_AS(FixedStepClock(0ms), std::invalid_argument);
}
