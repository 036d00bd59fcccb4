// SPDX-License-Identifier: GPL-2.0-or-later
// TopicSubscription: one hub connection's subscriptions to one topic, with rosbridge's throttle and queue
// semantics (rosbridge_suite's ROSBRIDGE_PROTOCOL.md, "subscribe"): throttle_rate is the least time in ms
// between two messages; queue_length messages wait out the throttle, the oldest replaced when full; several
// subscriptions to one topic send at the lowest throttle_rate and the highest queue_length. Kept apart from
// RosbridgeHub (which owns one per connection and topic, behind its mutex) so that the timing rule reads on its
// own and knows nothing of queues, connections or locks. Not thread-safe; the clock is passed in.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "ros/bridge/outbound_queue.hpp"

namespace rfbsim::ros {

/// One subscription's options, as a subscribe op gave them (already validated).
struct SubscribeOptions {
  std::string id;         ///< the op's id ("" when none); unsubscribe by id removes only this one
  int throttle_ms = 0;    ///< least time between two messages sent, ms (0: every message)
  int queue_length = 0;   ///< messages held back by the throttle (0: a throttled message is dropped)
};

/// A connection's subscriptions to one topic, merged, and the messages their throttle holds back.
struct TopicSubscription {
  using Clock = std::chrono::steady_clock;

  std::map<std::string, SubscribeOptions> by_id;  ///< "" for subscriptions without an id; never empty once merged
  int throttle_ms = 0;                            ///< merged over by_id: the lowest, ms
  int queue_length = 0;                           ///< merged over by_id: the longest
  std::optional<Clock::time_point> last_sent;     ///< when a message last went out; none before the first
  std::deque<Frame> pending;                      ///< held back by the throttle, at most queue_length

  /// Recomputes throttle_ms and queue_length from by_id (which must not be empty) and drops the oldest
  /// held-back messages beyond the new queue_length.
  void merge();
  /// A new message at `now`: true when it goes out now (the caller queues it; last_sent is now). Otherwise it
  /// is held back, or dropped when queue_length is 0; `throttled` counts each message dropped (the new one, or
  /// the oldest held back when the queue was full).
  bool offer(const Frame& frame, Clock::time_point now, std::uint64_t& throttled);
  /// The oldest held-back message if its time has come at `now`, taken (last_sent is then now); else null.
  Frame take_due(Clock::time_point now);
  /// When the oldest held-back message falls due; nullopt when none is held back.
  [[nodiscard]] std::optional<Clock::time_point> next_due() const;
};

}  // namespace rfbsim::ros
