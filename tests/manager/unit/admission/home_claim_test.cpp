// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "admission/home_claim.hpp"

using rfbsim::manager::Claim;
using rfbsim::manager::ClaimInputs;
using rfbsim::manager::home_claim;

namespace {

ClaimInputs new_uid_with_room() {
  ClaimInputs in;
  in.has_session = false;
  in.live_sessions = 1;
  in.max_sessions = 4;
  return in;
}

}  // namespace

TEST_CASE("home claim: a uid new here with room is claimed - one with a session here is not") {
  ClaimInputs in = new_uid_with_room();
  CHECK(home_claim(in) == Claim::kYes);
  in.has_session = true;
  CHECK(home_claim(in) == Claim::kNo);
}

TEST_CASE("home claim: an index that cannot be read asks for a retry") {
  ClaimInputs in = new_uid_with_room();
  in.has_session.reset();
  CHECK(home_claim(in) == Claim::kUnknown);
}

TEST_CASE("home claim: claims in flight hold slots, so the last slot is claimed once - full or draining only learns") {
  ClaimInputs in = new_uid_with_room();
  in.live_sessions = 3;
  CHECK(home_claim(in) == Claim::kYes);
  in.claims_in_flight = 1;
  CHECK(home_claim(in) == Claim::kLearn);
  in = new_uid_with_room();
  in.draining = true;
  CHECK(home_claim(in) == Claim::kLearn);
  in.shutting_down = true;
  CHECK(home_claim(in) == Claim::kNo);
}
