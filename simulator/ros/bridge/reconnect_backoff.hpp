// SPDX-License-Identifier: GPL-2.0-or-later
// ReconnectBackoff: how long the dial-out client waits before its next attempt. Waits start at kFirst and
// double up to a maximum; each one is spread by +-25 % so that many sessions dialling one lab after its
// restart do not all come back in the same instant. Pure: the caller passes the random draw.
#pragma once

#include <chrono>

namespace rfbsim::ros {

class ReconnectBackoff {
 public:
  /// `max_wait`: the longest wait before jitter (at least kFirst).
  explicit ReconnectBackoff(std::chrono::milliseconds max_wait);

  /// The wait before the next attempt, then doubles the base. `unit` in [0, 1) picks the jitter: 0 gives
  /// 75 % of the base, 0.5 the base itself, just under 1 gives 125 %.
  std::chrono::milliseconds next(double unit);
  /// Back to kFirst (after a connection that lasted).
  void reset() { base_ = kFirst; }

  /// The first wait, before jitter.
  static constexpr std::chrono::milliseconds kFirst{500};
  /// The spread of each wait around its base, as a fraction.
  static constexpr double kJitter = 0.25;

 private:
  const std::chrono::milliseconds max_;
  std::chrono::milliseconds base_ = kFirst;
};

}  // namespace rfbsim::ros
