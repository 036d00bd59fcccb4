// SPDX-License-Identifier: GPL-2.0-or-later
// Key bindings of the avatar and its camera.
#include "avatar/avatar_controls.hpp"

namespace rfbsim::sim {

namespace {
constexpr std::uint32_t kKeyUp = 0xff52;    // XK_Up
constexpr std::uint32_t kKeyDown = 0xff54;  // XK_Down
}  // namespace

std::uint32_t fold_letter_case(std::uint32_t keysym) {
  return (keysym >= 'A' && keysym <= 'Z') ? keysym + ('a' - 'A') : keysym;
}

bool AvatarControls::apply_key(std::uint32_t keysym, bool down) {
  // A release in the other case (Shift pressed or let go in between) still releases the key.
  switch (fold_letter_case(keysym)) {
    case 'w': state_.forward = down; return true;
    case 's': state_.backward = down; return true;
    case 'a': state_.turn_left = down; return true;
    case 'd': state_.turn_right = down; return true;
    case kKeyUp: state_.camera_up = down; return true;
    case kKeyDown: state_.camera_down = down; return true;
    default: return false;
  }
}

}  // namespace rfbsim::sim
