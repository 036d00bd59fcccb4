// SPDX-License-Identifier: GPL-2.0-or-later
// OutboundQueue: a byte-bounded FIFO that drops from the front.
#include "ros/bridge/outbound_queue.hpp"

#include <algorithm>

namespace rfbsim::ros {

bool OutboundQueue::push(Frame frame) {
  const bool was_empty = frames_.empty();
  bytes_ += frame->size();
  frames_.push_back(std::move(frame));
  // Oldest first: the newest frame stays even when it alone is over the bound.
  while (bytes_ > max_bytes_ && frames_.size() > 1) {
    bytes_ -= frames_.front()->size();
    frames_.pop_front();
    ++dropped_;
  }
  peak_bytes_ = std::max(peak_bytes_, bytes_);
  return was_empty;
}

std::deque<Frame> OutboundQueue::pop(std::size_t max_bytes) {
  std::deque<Frame> taken;
  std::size_t taken_bytes = 0;
  while (!frames_.empty()) {
    const std::size_t size = frames_.front()->size();
    // At least one frame, so that a frame larger than any budget still goes out.
    if (!taken.empty() && taken_bytes + size > max_bytes) break;
    taken_bytes += size;
    bytes_ -= size;
    taken.push_back(std::move(frames_.front()));
    frames_.pop_front();
  }
  return taken;
}

}  // namespace rfbsim::ros
