// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::InputEvent and rfbsim::InputQueue: the participant's keys and pointer, timestamped.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

namespace rfbsim {

/// One key or pointer event from a client, stamped with the server's steady clock when it arrived.
struct InputEvent {
  enum class Kind : std::uint8_t { Key, Pointer };
  Kind kind = Kind::Key;
  std::chrono::steady_clock::time_point time{};  ///< arrival time on the network thread
  int client_id = 0;                             ///< the server's id of the sending client; 0 = synthetic
  // Key events
  std::uint32_t keysym = 0;  ///< X11 keysym, e.g. 'w' 0x77, 'W' 0x57, Up 0xff52
  bool down = false;         ///< true on press, false on release
  // Pointer events
  int x = 0;                 ///< framebuffer pixels, 0 = left
  int y = 0;                 ///< framebuffer pixels, 0 = top
  std::uint8_t buttons = 0;  ///< RFB button mask: bit 0 left, 1 middle, 2 right, 3/4 wheel
};

/// A bounded multi-producer, single-consumer queue of input events. Thread-safe.
/// When full, the oldest pointer motion is dropped first, so key presses and releases are never lost.
class InputQueue {
 public:
  /// capacity: the most events held before dropping (> 0).
  explicit InputQueue(std::size_t capacity = 4096);

  /// Appends one event (network thread).
  void push(const InputEvent& event);
  /// Removes and returns every queued event in arrival order (simulation thread).
  std::vector<InputEvent> drain();
  /// Number of events dropped because the queue was full.
  [[nodiscard]] std::uint64_t dropped() const;

 private:
  mutable std::mutex mutex_;
  std::deque<InputEvent> events_;
  std::size_t capacity_;
  std::uint64_t dropped_ = 0;
};

}  // namespace rfbsim
