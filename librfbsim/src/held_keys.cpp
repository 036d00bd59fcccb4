// SPDX-License-Identifier: GPL-2.0-or-later
// HeldKeys: release tracking for keys whose release never arrived.
#include "held_keys.hpp"

namespace rfbsim::detail {

namespace {
InputEvent make_release(std::uint32_t keysym, std::chrono::steady_clock::time_point now) {
  InputEvent release;
  release.kind = InputEvent::Kind::Key;
  release.time = now;
  release.client_id = 0;  // synthetic
  release.keysym = keysym;
  release.down = false;
  return release;
}
}  // namespace

void HeldKeys::record(const InputEvent& key_event) {
  if (key_event.kind != InputEvent::Kind::Key) return;
  if (key_event.down) {
    held_[key_event.keysym][key_event.client_id] = true;
    return;
  }
  auto it = held_.find(key_event.keysym);
  if (it == held_.end()) return;
  it->second.erase(key_event.client_id);
  if (it->second.empty()) held_.erase(it);
}

std::vector<InputEvent> HeldKeys::release_client(int client_id,
                                                 std::chrono::steady_clock::time_point now) {
  std::vector<InputEvent> releases;
  for (auto it = held_.begin(); it != held_.end();) {
    auto& holders = it->second;
    // Only a key that nobody else still holds is released for the simulation.
    if (holders.erase(client_id) != 0 && holders.empty()) {
      releases.push_back(make_release(it->first, now));
    }
    it = holders.empty() ? held_.erase(it) : std::next(it);
  }
  return releases;
}

std::vector<InputEvent> HeldKeys::release_all(std::chrono::steady_clock::time_point now) {
  std::vector<InputEvent> releases;
  releases.reserve(held_.size());
  for (const auto& entry : held_) releases.push_back(make_release(entry.first, now));
  held_.clear();
  return releases;
}

bool HeldKeys::is_held(std::uint32_t keysym) const { return held_.count(keysym) != 0; }

}  // namespace rfbsim::detail
