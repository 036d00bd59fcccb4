// SPDX-License-Identifier: GPL-2.0-or-later
// AvatarControls: turns X11 key events into what the participant is asking the avatar to do.
#pragma once

#include <cstdint>

namespace rfbsim::sim {

/// Which controls are held now. W/S walk forward/backward, A/D turn left/right (keyboard only: a survey
/// participant has no mouse-look), Up/Down raise/lower the camera. Letter keys work in both cases.
struct ControlState {
  bool forward = false;
  bool backward = false;
  bool turn_left = false;
  bool turn_right = false;
  bool camera_up = false;
  bool camera_down = false;
  friend bool operator==(const ControlState&, const ControlState&) = default;
};

/// Keeps ControlState in step with key presses and releases.
class AvatarControls {
 public:
  /// Applies one key event (X11 keysym). Returns false when the key controls nothing.
  bool apply_key(std::uint32_t keysym, bool down);
  /// Releases everything (e.g. when the participant leaves).
  void release_all() { state_ = {}; }
  [[nodiscard]] const ControlState& state() const { return state_; }

 private:
  ControlState state_;
};

/// Lower-cases ASCII letter keysyms ('W' 0x57 -> 'w' 0x77); other keysyms pass unchanged.
std::uint32_t fold_letter_case(std::uint32_t keysym);

}  // namespace rfbsim::sim
