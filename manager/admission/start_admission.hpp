// SPDX-License-Identifier: GPL-2.0-or-later
// StartAdmission: who may start a session with a /start link, decided from the link and its sender alone:
// the sender's rate, the query's shape, the signature, the parameters, the ROS section and the link's expiry,
// in that order. Pure: time is passed in, nothing is read or written, so every rule is unit-tested without a
// socket. The HTTP layer turns a decision into a response; what the supervisor decides next (a free slot, a
// completed uid, unspent sessions) and the cluster's claim (home_claim.hpp) come after it.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "admin/metrics.hpp"
#include "admission/rate_limiter.hpp"
#include "admission/start_request.hpp"
#include "config/config.hpp"

namespace rfbsim::manager {

/// What /start is answered before any session is looked at.
struct StartDecision {
  enum class Kind {
    kAdmitted,     ///< `request` may go on to the supervisor (and, with several hosts, the uid registry)
    kRateLimited,  ///< the sender's bucket is empty: 429 with the busy page, retry after `retry_after`
    kRefused,      ///< `status` with an error page of `title` and `message`, counted as `rejection`
  };
  Kind kind = Kind::kRefused;
  std::optional<StartRequest> request;   ///< kAdmitted
  std::chrono::seconds retry_after{0};   ///< kRateLimited
  int status = 0;                        ///< kRefused: 400, 403 or 410
  Rejection rejection = Rejection::kBadRequest;
  std::string title;
  std::string message;
};

class StartAdmission {
 public:
  /// Keeps `config` (which must outlive it) and a /start bucket per address from its abuse limits.
  explicit StartAdmission(const ManagerConfig& config);

  /// Decides on a /start with `query` (the raw query string) from `address` (the sender's abuse key) at
  /// `now`, a link's expiry compared with `unix_now` (seconds). Takes one token of the address's bucket. A valid
  /// `camera` is refused (400) where config.allow_camera_param is off.
  StartDecision decide(const std::string& query, const std::string& address,
                       std::chrono::steady_clock::time_point now, long long unix_now);

 private:
  const ManagerConfig& config_;
  RateLimiter limiter_;
};

}  // namespace rfbsim::manager
