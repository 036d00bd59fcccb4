// SPDX-License-Identifier: GPL-2.0-or-later
// FrameMailbox: hands the newest frame from the simulation thread to the network thread.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim::detail {

/// A single-slot, latest-wins mailbox of tightly packed RGBA frames of one size. Thread-safe.
/// post() copies into a spare buffer and swaps it in under a short lock; take() swaps the newest frame
/// out. Neither side ever waits for the other beyond a pointer swap, and an unread frame is replaced.
class FrameMailbox {
 public:
  FrameMailbox(int width, int height);

  /// Copies `frame` (must be width x height) into the slot, replacing an unread one.
  void post(const FrameView& frame);
  /// If a frame arrived since the last take, swaps it into `out` (resized as needed) and returns true.
  bool take(std::vector<std::uint8_t>& out);
  /// Frames replaced before the network thread took them.
  [[nodiscard]] std::uint64_t overwritten() const;

 private:
  std::size_t frame_bytes_;
  std::size_t row_bytes_;
  int height_;
  mutable std::mutex mutex_;
  std::vector<std::uint8_t> slot_;     // newest complete frame, guarded by mutex_
  bool slot_full_ = false;             // guarded by mutex_
  std::uint64_t overwritten_ = 0;      // guarded by mutex_
  std::mutex writer_mutex_;            // serialises posters; guards spare_
  std::vector<std::uint8_t> spare_;    // the poster's scratch buffer, filled outside mutex_
};

}  // namespace rfbsim::detail
