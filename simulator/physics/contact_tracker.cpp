// SPDX-License-Identifier: GPL-2.0-or-later
// ContactTracker: once-per-touch contact events from per-tick pair impulses.
#include "physics/contact_tracker.hpp"

#include <cassert>
#include <utility>

namespace rfbsim::sim {

ContactTracker::ContactTracker(std::vector<PartyRef> slots) : slots_(std::move(slots)) {
  const std::size_t n = slots_.size();
  pairs_.resize(n * n);  // only the upper triangle is used; n is a few dozen at most
}

std::size_t ContactTracker::pair_index(int a, int b) const {
  assert(a != b && a >= 0 && b >= 0 && a < size() && b < size() && "ContactTracker: bad slot");
  if (a > b) std::swap(a, b);
  return static_cast<std::size_t>(a) * slots_.size() + static_cast<std::size_t>(b);
}

void ContactTracker::begin_tick() {
  for (PairState& pair : pairs_) {
    pair.impulse = 0.0;
    pair.touched = false;
  }
}

void ContactTracker::add(int a, int b, double impulse) {
  PairState& pair = pairs_[pair_index(a, b)];
  pair.touched = true;
  pair.impulse += impulse;
}

void ContactTracker::end_tick(std::uint64_t tick, double min_impulse, std::vector<ContactEvent>& events) {
  // Slots are in Party order and people by index, so a < b gives the event's party order directly.
  for (int a = 0; a < size(); ++a) {
    for (int b = a + 1; b < size(); ++b) {
      PairState& pair = pairs_[pair_index(a, b)];
      if (!pair.touched) {
        // Separated: the next contact is a new touch.
        pair.touching = false;
        pair.reported = false;
        continue;
      }
      if (!pair.touching) pair.reported = false;
      pair.touching = true;
      // A graze below the threshold is not news; the touch is reported when it first pushes hard enough.
      if (pair.reported || pair.impulse < min_impulse) continue;
      pair.reported = true;
      const PartyRef& first = slots_[static_cast<std::size_t>(a)];
      const PartyRef& second = slots_[static_cast<std::size_t>(b)];
      events.push_back(ContactEvent{tick, first.party, first.index, second.party, second.index, pair.impulse});
    }
  }
}

}  // namespace rfbsim::sim
