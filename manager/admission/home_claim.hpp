// SPDX-License-Identifier: GPL-2.0-or-later
// With several hosts, whether /start of a uid must ask the uid registry first, and what for. Pure: the
// supervisor's answers are passed in, so the rule is unit-tested without sockets.
#pragma once

#include <optional>

namespace rfbsim::manager {

enum class Claim {
  kNo,       ///< this host has a session of the uid, or is shutting down: it answers alone
  kYes,      ///< a uid new here, and a free slot: the registry decides where it starts
  kLearn,    ///< a uid new here, but full or draining: the registry only tells whether it lives elsewhere
  kUnknown,  ///< the index could not be read: the participant retries in a moment
};

/// What this host knows when /start of a uid arrives.
struct ClaimInputs {
  std::optional<bool> has_session;  ///< the uid has a session here; unset = the index could not be read
  bool shutting_down = false;
  bool draining = false;
  int live_sessions = 0;
  int claims_in_flight = 0;  ///< claim rounds started here and not yet decided
  int max_sessions = 0;
};

/// A full or draining host claims nothing (its busy page sends the participant elsewhere, and nothing was
/// recorded); it only learns whether the uid already has a home on another host, to send it there. Claims
/// still deciding hold a slot each: two new uids must not both win this host's last slot, or the loser would
/// be homed here for good while other hosts have room.
Claim home_claim(const ClaimInputs& in);

}  // namespace rfbsim::manager
