// SPDX-License-Identifier: GPL-2.0-or-later
// HeldKeys: which keys clients hold down, so that they can be released when the clients leave.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <vector>

#include "rfbsim/input.hpp"

namespace rfbsim::detail {

/// Counts presses per keysym across clients. Not thread-safe: the network thread owns it.
class HeldKeys {
 public:
  /// Records a key event (presses and releases; repeats of a held key are counted once).
  void record(const InputEvent& key_event);
  /// Release events for every key still held by `client_id`, which are then forgotten.
  std::vector<InputEvent> release_client(int client_id, std::chrono::steady_clock::time_point now);
  /// Release events for every key still held by anyone; everything is forgotten.
  std::vector<InputEvent> release_all(std::chrono::steady_clock::time_point now);
  /// Whether any client holds `keysym`.
  [[nodiscard]] bool is_held(std::uint32_t keysym) const;
  [[nodiscard]] bool empty() const { return held_.empty(); }

 private:
  std::map<std::uint32_t, std::map<int, bool>> held_;  // keysym -> clients holding it
};

}  // namespace rfbsim::detail
