// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <thread>

#include "rfbsim/input.hpp"

using rfbsim::InputEvent;
using rfbsim::InputQueue;

namespace {
InputEvent key(std::uint32_t keysym, bool down) {
  InputEvent e;
  e.kind = InputEvent::Kind::Key;
  e.keysym = keysym;
  e.down = down;
  return e;
}
InputEvent pointer(int x) {
  InputEvent e;
  e.kind = InputEvent::Kind::Pointer;
  e.x = x;
  return e;
}
}  // namespace

TEST_CASE("drain returns events in arrival order and empties the queue") {
  InputQueue queue;
  queue.push(key('w', true));
  queue.push(pointer(3));
  queue.push(key('w', false));
  const auto events = queue.drain();
  REQUIRE(events.size() == 3);
  CHECK(events[0].keysym == 'w');
  CHECK(events[0].down);
  CHECK(events[1].x == 3);
  CHECK_FALSE(events[2].down);
  CHECK(queue.drain().empty());
}

TEST_CASE("a full queue drops pointer motion before keys") {
  InputQueue queue(3);
  queue.push(pointer(1));
  queue.push(key('a', true));
  queue.push(pointer(2));
  queue.push(key('a', false));  // drops pointer 1
  queue.push(pointer(3));       // drops pointer 2
  queue.push(key('d', true));   // drops pointer 3
  const auto events = queue.drain();
  REQUIRE(events.size() == 3);
  CHECK(events[0].keysym == 'a');
  CHECK(events[1].keysym == 'a');
  CHECK(events[2].keysym == 'd');
  CHECK(queue.dropped() == 3);
}

TEST_CASE("a queue full of keys drops the new pointer event - then the oldest key") {
  InputQueue queue(2);
  queue.push(key('a', true));
  queue.push(key('b', true));
  queue.push(pointer(1));
  CHECK(queue.dropped() == 1);
  queue.push(key('c', true));
  const auto events = queue.drain();
  REQUIRE(events.size() == 2);
  CHECK(events[0].keysym == 'b');
  CHECK(events[1].keysym == 'c');
}

TEST_CASE("concurrent producers lose nothing below capacity") {
  InputQueue queue(100000);
  std::thread a([&] { for (int i = 0; i < 5000; ++i) queue.push(key('a', true)); });
  std::thread b([&] { for (int i = 0; i < 5000; ++i) queue.push(key('b', true)); });
  std::size_t total = 0;
  while (total < 10000) total += queue.drain().size();
  a.join();
  b.join();
  CHECK(total == 10000);
  CHECK(queue.dropped() == 0);
}
