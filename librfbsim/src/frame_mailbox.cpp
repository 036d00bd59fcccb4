// SPDX-License-Identifier: GPL-2.0-or-later
// FrameMailbox: copy outside the lock, swap inside it.
#include "frame_mailbox.hpp"

#include <cstring>

namespace rfbsim::detail {

FrameMailbox::FrameMailbox(int width, int height)
    : frame_bytes_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4U),
      row_bytes_(static_cast<std::size_t>(width) * 4U),
      height_(height) {}

void FrameMailbox::post(const FrameView& frame) {
  std::lock_guard writer(writer_mutex_);
  spare_.resize(frame_bytes_);
  // The expensive copy happens before taking the shared lock, so the reader never waits on it.
  if (frame.row_bytes() == row_bytes_) {
    std::memcpy(spare_.data(), frame.pixels, frame_bytes_);
  } else {
    for (int y = 0; y < height_; ++y) {
      std::memcpy(spare_.data() + static_cast<std::size_t>(y) * row_bytes_, frame.row(y), row_bytes_);
    }
  }
  std::lock_guard lock(mutex_);
  if (slot_full_) ++overwritten_;
  slot_.swap(spare_);
  slot_full_ = true;
}

bool FrameMailbox::take(std::vector<std::uint8_t>& out) {
  std::lock_guard lock(mutex_);
  if (!slot_full_) return false;
  out.swap(slot_);
  slot_full_ = false;
  return true;
}

std::uint64_t FrameMailbox::overwritten() const {
  std::lock_guard lock(mutex_);
  return overwritten_;
}

}  // namespace rfbsim::detail
