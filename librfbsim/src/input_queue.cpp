// SPDX-License-Identifier: GPL-2.0-or-later
// The bounded input queue between the network thread and the simulation thread.
#include <algorithm>
#include <stdexcept>

#include "rfbsim/input.hpp"

namespace rfbsim {

InputQueue::InputQueue(std::size_t capacity) : capacity_(capacity) {
  if (capacity == 0) throw std::invalid_argument("InputQueue: capacity must be positive");
}

void InputQueue::push(const InputEvent& event) {
  std::lock_guard lock(mutex_);
  if (events_.size() >= capacity_) {
    // Pointer motion is the flood; keys carry state the simulation must see, so drop motion first.
    auto oldest_pointer = std::find_if(events_.begin(), events_.end(), [](const InputEvent& e) {
      return e.kind == InputEvent::Kind::Pointer;
    });
    if (oldest_pointer != events_.end()) {
      events_.erase(oldest_pointer);
    } else if (event.kind == InputEvent::Kind::Pointer) {
      ++dropped_;
      return;
    } else {
      events_.pop_front();
    }
    ++dropped_;
  }
  events_.push_back(event);
}

std::vector<InputEvent> InputQueue::drain() {
  std::lock_guard lock(mutex_);
  std::vector<InputEvent> out(events_.begin(), events_.end());
  events_.clear();
  return out;
}

std::uint64_t InputQueue::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace rfbsim
