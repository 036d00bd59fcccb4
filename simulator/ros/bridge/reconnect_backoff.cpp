// SPDX-License-Identifier: GPL-2.0-or-later
// ReconnectBackoff: doubling waits with +-25 % jitter.
#include "ros/bridge/reconnect_backoff.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::ros {

ReconnectBackoff::ReconnectBackoff(std::chrono::milliseconds max_wait) : max_(std::max(max_wait, kFirst)) {}

std::chrono::milliseconds ReconnectBackoff::next(double unit) {
  const double spread = 1.0 - kJitter + 2.0 * kJitter * std::clamp(unit, 0.0, 1.0);
  const auto wait = std::chrono::milliseconds(std::llround(static_cast<double>(base_.count()) * spread));
  base_ = std::min<std::chrono::milliseconds>(base_ * 2, max_);
  return wait;
}

}  // namespace rfbsim::ros
