// SPDX-License-Identifier: GPL-2.0-or-later
#include "admission/home_claim.hpp"

namespace rfbsim::manager {

Claim home_claim(const ClaimInputs& in) {
  if (!in.has_session) return Claim::kUnknown;
  if (*in.has_session || in.shutting_down) return Claim::kNo;
  const bool full = in.live_sessions + in.claims_in_flight >= in.max_sessions;
  return full || in.draining ? Claim::kLearn : Claim::kYes;
}

}  // namespace rfbsim::manager
