// SPDX-License-Identifier: GPL-2.0-or-later
// ContactTracker: one event per touch, parties in order, the impulse threshold.
#include "physics/contact_tracker.hpp"

#include <catch2/catch.hpp>

#include <initializer_list>
#include <tuple>
#include <vector>

using rfbsim::sim::ContactEvent;
using rfbsim::sim::ContactTracker;
using rfbsim::sim::Party;
using rfbsim::sim::PartyRef;

namespace {

// Slots: 0 avatar, 1 people[0], 2 people[1], 3 robot, 4 static.
ContactTracker make_tracker() {
  return ContactTracker({{Party::Avatar, 0}, {Party::Person, 0}, {Party::Person, 1}, {Party::Robot, 0},
                         {Party::Static, 0}});
}

// One tick with the given touches (slot, slot, impulse N s) and a 0.5 N s threshold; returns its events.
std::vector<ContactEvent> tick(ContactTracker& tracker, std::uint64_t t,
                               std::initializer_list<std::tuple<int, int, double>> touches) {
  tracker.begin_tick();
  for (const auto& [a, b, impulse] : touches) tracker.add(a, b, impulse);
  std::vector<ContactEvent> events;
  tracker.end_tick(t, 0.5, events);
  return events;
}

}  // namespace

TEST_CASE("a touch is reported once, at its first tick, and again only after separating") {
  ContactTracker tracker = make_tracker();
  auto events = tick(tracker, 10, {{0, 3, 2.0}, {0, 3, 1.0}});
  REQUIRE(events.size() == 1);
  CHECK(events[0].tick == 10);
  CHECK(events[0].a == Party::Avatar);
  CHECK(events[0].b == Party::Robot);
  CHECK(events[0].impulse == 3.0);  // summed over the tick's contact points
  CHECK(tick(tracker, 11, {{3, 0, 5.0}}).empty());  // still touching
  CHECK(tick(tracker, 12, {}).empty());            // separated
  events = tick(tracker, 13, {{0, 3, 1.0}});
  REQUIRE(events.size() == 1);
  CHECK(events[0].tick == 13);
}

TEST_CASE("parties are ordered avatar < person < robot < static, with people's indices") {
  ContactTracker tracker = make_tracker();
  const auto events = tick(tracker, 0, {{4, 2, 1.0}, {3, 1, 1.0}, {2, 1, 1.0}});
  REQUIRE(events.size() == 3);
  CHECK((events[0].a == Party::Person && events[0].a_index == 0));
  CHECK((events[0].b == Party::Person && events[0].b_index == 1));
  CHECK((events[1].a == Party::Person && events[1].a_index == 0 && events[1].b == Party::Robot));
  CHECK((events[2].a == Party::Person && events[2].a_index == 1 && events[2].b == Party::Static));
}

TEST_CASE("a graze below the threshold is not reported until the same touch pushes hard enough") {
  ContactTracker tracker = make_tracker();
  CHECK(tick(tracker, 0, {{1, 4, 0.2}}).empty());
  const auto events = tick(tracker, 1, {{1, 4, 0.7}});
  REQUIRE(events.size() == 1);
  CHECK(events[0].tick == 1);
  CHECK(events[0].impulse == 0.7);
  CHECK(tick(tracker, 2, {{1, 4, 0.9}}).empty());
}
