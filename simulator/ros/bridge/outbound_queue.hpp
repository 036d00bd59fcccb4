// SPDX-License-Identifier: GPL-2.0-or-later
// OutboundQueue: the frames waiting for one rosbridge connection, bounded in bytes. A client that reads
// slower than the simulation publishes loses its oldest frames, never the server's memory: live robot data
// is only worth its newest values. Not thread-safe; RosbridgeHub guards it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace rfbsim::ros {

/// One serialized rosbridge message; shared, because one publish fans out to every subscriber unchanged.
using Frame = std::shared_ptr<const std::string>;

class OutboundQueue {
 public:
  /// `max_bytes`: the most frame bytes held; the newest frame is always kept, even when alone it is larger.
  explicit OutboundQueue(std::size_t max_bytes) : max_bytes_(max_bytes) {}

  /// Appends `frame`, then drops the oldest frames until the queue fits. Returns true when it was empty before.
  bool push(Frame frame);
  /// Pops the oldest frames: at least one (when any), then more while their total stays within `max_bytes`.
  std::deque<Frame> pop(std::size_t max_bytes);

  [[nodiscard]] bool empty() const { return frames_.empty(); }
  [[nodiscard]] std::size_t bytes() const { return bytes_; }
  /// The most bytes held at once since construction.
  [[nodiscard]] std::size_t peak_bytes() const { return peak_bytes_; }
  /// Frames dropped to stay within the bound since construction.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  std::size_t max_bytes_;
  std::deque<Frame> frames_;
  std::size_t bytes_ = 0;
  std::size_t peak_bytes_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace rfbsim::ros
