// SPDX-License-Identifier: GPL-2.0-or-later
// TopicSubscription: merging subscribe ops and rosbridge's throttle_rate/queue_length timing (see the header).
#include "ros/bridge/topic_subscription.hpp"

#include <algorithm>
#include <cstddef>

namespace rfbsim::ros {

void TopicSubscription::merge() {
  throttle_ms = by_id.begin()->second.throttle_ms;
  queue_length = 0;
  for (const auto& [id, options] : by_id) {
    throttle_ms = std::min(throttle_ms, options.throttle_ms);
    queue_length = std::max(queue_length, options.queue_length);
  }
  while (pending.size() > static_cast<std::size_t>(queue_length)) pending.pop_front();
}

bool TopicSubscription::offer(const Frame& frame, Clock::time_point now, std::uint64_t& throttled) {
  // Unthrottled, or the throttle's time has passed with nothing waiting ahead of it: out at once.
  const auto throttle = std::chrono::milliseconds(throttle_ms);
  const bool due = !last_sent || now - *last_sent >= throttle;
  if (throttle_ms == 0 || (due && pending.empty())) {
    last_sent = now;
    return true;
  }
  // Held back behind the throttle, the oldest giving way when the queue is full; no queue: dropped.
  if (queue_length == 0) {
    ++throttled;
    return false;
  }
  pending.push_back(frame);
  if (pending.size() > static_cast<std::size_t>(queue_length)) {
    pending.pop_front();
    ++throttled;
  }
  return false;
}

Frame TopicSubscription::take_due(Clock::time_point now) {
  if (pending.empty()) return nullptr;
  const auto throttle = std::chrono::milliseconds(throttle_ms);
  if (last_sent && now - *last_sent < throttle) return nullptr;
  last_sent = now;
  Frame frame = pending.front();
  pending.pop_front();
  return frame;
}

std::optional<TopicSubscription::Clock::time_point> TopicSubscription::next_due() const {
  // A message is only ever held back after one went out (a first message goes at once), so last_sent is set.
  if (pending.empty()) return std::nullopt;
  return *last_sent + std::chrono::milliseconds(throttle_ms);
}

}  // namespace rfbsim::ros
