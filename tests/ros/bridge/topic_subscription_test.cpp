// SPDX-License-Identifier: GPL-2.0-or-later
// TopicSubscription on its own, on hand-set times: merging subscribe ops, what goes out at once, what the
// throttle holds back or drops, and when the next held-back message falls due.
#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "ros/bridge/topic_subscription.hpp"

using namespace rfbsim::ros;
using Clock = TopicSubscription::Clock;
using std::chrono::milliseconds;

namespace {

Frame frame_of(const std::string& text) { return std::make_shared<const std::string>(text); }

// A subscription merged from one subscribe op.
TopicSubscription subscribed(int throttle_ms, int queue_length) {
  TopicSubscription subscription;
  subscription.by_id[""] = SubscribeOptions{"", throttle_ms, queue_length};
  subscription.merge();
  return subscription;
}

}  // namespace

TEST_CASE("topic subscription: unthrottled, every message goes out at once") {
  TopicSubscription subscription = subscribed(0, 0);
  std::uint64_t throttled = 0;
  const Clock::time_point t0{};
  CHECK(subscription.offer(frame_of("a"), t0, throttled));
  CHECK(subscription.offer(frame_of("b"), t0, throttled));
  CHECK(throttled == 0);
  CHECK_FALSE(subscription.next_due());
}

TEST_CASE("topic subscription: a throttle without a queue drops what comes too soon") {
  TopicSubscription subscription = subscribed(100, 0);
  std::uint64_t throttled = 0;
  const Clock::time_point t0{};
  CHECK(subscription.offer(frame_of("a"), t0, throttled));
  CHECK_FALSE(subscription.offer(frame_of("b"), t0 + milliseconds(99), throttled));
  CHECK(throttled == 1);
  CHECK(subscription.offer(frame_of("c"), t0 + milliseconds(100), throttled));
  CHECK(throttled == 1);
}

TEST_CASE("topic subscription: a queue holds the newest messages and releases one per throttle") {
  TopicSubscription subscription = subscribed(100, 2);
  std::uint64_t throttled = 0;
  const Clock::time_point t0{};
  CHECK(subscription.offer(frame_of("a"), t0, throttled));
  CHECK_FALSE(subscription.offer(frame_of("b"), t0 + milliseconds(10), throttled));
  CHECK_FALSE(subscription.offer(frame_of("c"), t0 + milliseconds(20), throttled));
  CHECK_FALSE(subscription.offer(frame_of("d"), t0 + milliseconds(30), throttled));  // "b" gives way
  CHECK(throttled == 1);
  CHECK(subscription.next_due() == t0 + milliseconds(100));
  CHECK(subscription.take_due(t0 + milliseconds(99)) == nullptr);
  const Frame first = subscription.take_due(t0 + milliseconds(100));
  REQUIRE(first != nullptr);
  CHECK(*first == "c");
  CHECK(subscription.next_due() == t0 + milliseconds(200));
  const Frame second = subscription.take_due(t0 + milliseconds(250));
  REQUIRE(second != nullptr);
  CHECK(*second == "d");
  CHECK_FALSE(subscription.next_due());
  CHECK(subscription.take_due(t0 + milliseconds(400)) == nullptr);
}

TEST_CASE("topic subscription: several ops merge to the lowest throttle and the longest queue") {
  TopicSubscription subscription;
  subscription.by_id["slow"] = SubscribeOptions{"slow", 500, 1};
  subscription.by_id["fast"] = SubscribeOptions{"fast", 50, 3};
  subscription.by_id["none"] = SubscribeOptions{"none", 200, 0};
  subscription.merge();
  CHECK(subscription.throttle_ms == 50);
  CHECK(subscription.queue_length == 3);

  // A shorter queue after a merge drops the oldest held-back messages.
  std::uint64_t throttled = 0;
  const Clock::time_point t0{};
  CHECK(subscription.offer(frame_of("a"), t0, throttled));
  for (const char* text : {"b", "c", "d"}) CHECK_FALSE(subscription.offer(frame_of(text), t0, throttled));
  subscription.by_id.erase("fast");
  subscription.merge();
  CHECK(subscription.throttle_ms == 200);
  CHECK(subscription.queue_length == 1);
  REQUIRE(subscription.pending.size() == 1);
  CHECK(*subscription.pending.front() == "d");
}
