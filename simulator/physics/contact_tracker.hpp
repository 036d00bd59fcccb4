// SPDX-License-Identifier: GPL-2.0-or-later
// ContactTracker: turns each tick's touching pairs and their impulses into ContactEvents, once per touch.
// Plain C++ (no ODE), so the reporting rules are tested on their own.
#pragma once

#include <cstdint>
#include <vector>

#include "world/world.hpp"

namespace rfbsim::sim {

/// One party a body stands for: the avatar, people[index], the robot, or all static geometry.
struct PartyRef {
  Party party = Party::Static;
  int index = 0;  ///< index into people for Party::Person; 0 otherwise
};

/// Pair bookkeeping over "slots", one per party, listed in Party order (avatar, people by index, robot,
/// static), so that iterating pairs by slot yields events already ordered as ContactEvent wants them.
class ContactTracker {
 public:
  /// Starts with nobody touching; `slots` must be in Party order.
  explicit ContactTracker(std::vector<PartyRef> slots = {});

  /// Number of slots.
  [[nodiscard]] int size() const { return static_cast<int>(slots_.size()); }

  /// Forgets this tick's touches (call before the tick's first add()).
  void begin_tick();

  /// Slots `a` and `b` (any order, a != b) touched during this tick with this much normal impulse, N s.
  void add(int a, int b, double impulse);

  /// Appends one event per new touch: a touch (a run of ticks with contact) is reported once, at its first
  /// tick whose impulse reaches `min_impulse`, with that tick's impulse; a pair that stays in contact is
  /// reported again only after a tick without contact.
  void end_tick(std::uint64_t tick, double min_impulse, std::vector<ContactEvent>& events);

 private:
  // Per unordered pair (upper triangle, row-major), what this tick and the running touch hold.
  struct PairState {
    double impulse = 0.0;   // N s, this tick
    bool touched = false;   // contact during this tick
    bool touching = false;  // in contact at the end of the last tick
    bool reported = false;  // the running touch has its event
  };
  [[nodiscard]] std::size_t pair_index(int a, int b) const;

  std::vector<PartyRef> slots_;
  std::vector<PairState> pairs_;
};

}  // namespace rfbsim::sim
