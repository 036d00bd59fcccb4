// SPDX-License-Identifier: GPL-2.0-or-later
// The wall clock as Unix seconds: what signed links' expiry and the cluster's registry messages carry.
#pragma once

#include <chrono>

namespace rfbsim::manager {

/// Seconds since the Unix epoch, now (the system clock: comparable across hosts, unlike the steady clock).
inline long long unix_seconds_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace rfbsim::manager
