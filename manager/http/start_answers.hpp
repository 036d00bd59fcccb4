// SPDX-License-Identifier: GPL-2.0-or-later
// The pages /start answers with, decided apart from the server: each outcome of the admission, the uid
// registry and the supervisor becomes a status, a page, its extra headers and the rejection it counts as.
// Pure: no I/O, so what a participant sees in each case is unit-tested without a socket.
#pragma once

#include <optional>
#include <string>

#include "admin/metrics.hpp"
#include "admission/start_admission.hpp"
#include "config/config.hpp"
#include "http/web_policy.hpp"
#include "sessions/supervisor.hpp"

namespace rfbsim::manager {

/// One answer to /start: an HTML page with `status` and `headers`, counted as `rejection` when set.
struct PageAnswer {
  int status = 200;
  std::string html;
  Headers headers;
  std::optional<Rejection> rejection;
};

/// A link the admission turned away (rate limited or refused).
PageAnswer answer_refused_start(const StartDecision& decision);

/// The supervisor's outcome: a redirect into the session, or a page saying why not.
PageAnswer answer_start_outcome(const StartOutcome& outcome, const ManagerConfig& config);

/// Too few hosts answered to decide a uid's home: nothing was decided, so a retry here or elsewhere is safe.
PageAnswer answer_home_undecided();

/// This host is full or draining and the uid has no home elsewhere: the busy page.
PageAnswer answer_busy();

/// 303 to the uid's home host's /start with the same query: the balancer routes /<home>/ to that host, which
/// serves the uid from now on.
PageAnswer answer_go_home(const std::string& home, const std::string& query);

}  // namespace rfbsim::manager
