// SPDX-License-Identifier: GPL-2.0-or-later
// FrameSchedule: when sim_rfb renders: at the frame rate while someone watches, and early for a key that changed
// what the avatar does.
//
// A key is applied at the next simulation tick, and without help its picture would wait for the next slot of the
// frame rate too: up to a whole frame interval (33 ms at 30 fps) on top, in every key-to-picture latency. So a
// change of the controls is rendered right after the tick that applied it, and the slots start again from that
// frame: at most one extra frame per key press or release, and never a burst. Knows nothing of rendering; time is
// passed in, so tests drive it with a fake clock.
#pragma once

#include <chrono>

namespace rfbsim::sim {

class FrameSchedule {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// `interval`: one frame at the frame rate (> 0).
  explicit FrameSchedule(Clock::duration interval) : interval_(interval) {}

  /// Input drained at `now` changed the controls (a press or a release; a held key's repeats do not).
  void controls_changed() { controls_to_show_ = true; }
  /// Whether to render at `now`, after `ticks` simulation ticks were stepped there (0: none yet), with
  /// `watched` false when nobody watches (then nothing is rendered, and the slots start again at the next
  /// viewer). When true, the frame is taken to be rendered now.
  bool render_now(TimePoint now, int ticks, bool watched);
  /// The next slot of the frame rate: wake by then while someone watches.
  [[nodiscard]] TimePoint next_frame() const { return next_frame_; }

 private:
  Clock::duration interval_;
  TimePoint next_frame_{};
  bool controls_to_show_ = false;
};

}  // namespace rfbsim::sim
