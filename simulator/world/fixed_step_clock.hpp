// SPDX-License-Identifier: GPL-2.0-or-later
// FixedStepClock: how many fixed simulation steps are due, whatever the frame rate.
#pragma once

#include <chrono>
#include <cstdint>

namespace rfbsim::sim {

/// Converts elapsed real time into a whole number of fixed steps, carrying the remainder. When the host
/// falls far behind (a stall, a debugger), it drops the backlog beyond `max_steps_per_call` instead of
/// spiralling, and counts what it dropped.
class FixedStepClock {
 public:
  using Duration = std::chrono::nanoseconds;

  /// dt: the fixed step (> 0); max_steps_per_call: the most steps advance() returns at once (> 0).
  FixedStepClock(Duration dt, int max_steps_per_call = 10);

  /// Adds `elapsed` real time; returns the number of steps to run now.
  int advance(Duration elapsed);
  /// Time left over toward the next step.
  [[nodiscard]] Duration remainder() const { return accumulated_; }
  /// Time until the next step is due.
  [[nodiscard]] Duration until_next_step() const { return dt_ - accumulated_; }
  [[nodiscard]] Duration step() const { return dt_; }
  [[nodiscard]] double step_seconds() const { return std::chrono::duration<double>(dt_).count(); }
  /// Steps skipped because the host fell behind.
  [[nodiscard]] std::uint64_t dropped_steps() const { return dropped_; }

 private:
  Duration dt_;
  int max_steps_;
  Duration accumulated_{0};
  std::uint64_t dropped_ = 0;
};

}  // namespace rfbsim::sim
