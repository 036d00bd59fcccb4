// SPDX-License-Identifier: GPL-2.0-or-later
// FrameSchedule: the frame rate's slots, and the early frame for a change of controls.
#include "app/frame_schedule.hpp"

namespace rfbsim::sim {

bool FrameSchedule::render_now(TimePoint now, int ticks, bool watched) {
  if (!watched) {
    next_frame_ = now;
    controls_to_show_ = false;
    return false;
  }
  // Only once a tick has applied the change: before that the picture would not show it yet.
  const bool show_controls = controls_to_show_ && ticks > 0;
  if (now < next_frame_ && !show_controls) return false;
  next_frame_ = show_controls ? now + interval_ : next_frame_ + interval_;
  if (next_frame_ < now) next_frame_ = now + interval_;  // fell behind: skip, do not burst
  controls_to_show_ = false;
  return true;
}

}  // namespace rfbsim::sim
