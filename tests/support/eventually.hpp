// SPDX-License-Identifier: GPL-2.0-or-later
// eventually(): polls a condition until it holds or a limit passes. The limit bounds a hang on a loaded machine;
// it measures nothing, so it is generous.
#pragma once

#include <chrono>
#include <thread>

namespace rfbsim::test {

/// Waits until `condition()` holds, checking every `poll`; once `limit` has passed, returns what one last look
/// at the condition says.
template <typename Condition>
bool eventually(Condition condition, std::chrono::milliseconds limit = std::chrono::seconds(15),
                std::chrono::milliseconds poll = std::chrono::milliseconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= deadline) return condition();
    std::this_thread::sleep_for(poll);
  }
  return true;
}

}  // namespace rfbsim::test
