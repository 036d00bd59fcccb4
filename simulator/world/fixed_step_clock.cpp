// SPDX-License-Identifier: GPL-2.0-or-later
// FixedStepClock: accumulate, divide, carry.
#include "world/fixed_step_clock.hpp"

#include <stdexcept>

namespace rfbsim::sim {

FixedStepClock::FixedStepClock(Duration dt, int max_steps_per_call) : dt_(dt), max_steps_(max_steps_per_call) {
  if (dt.count() <= 0 || max_steps_per_call <= 0) {
    throw std::invalid_argument("FixedStepClock: step and max steps must be positive");
  }
}

int FixedStepClock::advance(Duration elapsed) {
  if (elapsed.count() > 0) accumulated_ += elapsed;
  auto due = accumulated_ / dt_;
  accumulated_ -= due * dt_;
  if (due > max_steps_) {
    dropped_ += static_cast<std::uint64_t>(due - max_steps_);
    due = max_steps_;
  }
  return static_cast<int>(due);
}

}  // namespace rfbsim::sim
