// SPDX-License-Identifier: GPL-2.0-or-later
#include "http/start_answers.hpp"

#include <algorithm>

#include "http/pages.hpp"

namespace rfbsim::manager {

namespace {

// How long the busy page waits before it tries the link again.
constexpr int kBusyRetrySeconds = 10;
// How long the "try again in a moment" page waits when too few hosts answered to decide a uid's home.
constexpr int kUndecidedRetrySeconds = 5;
// How long the "previous session is closing" page waits: an ending session is gone within the stop grace.
constexpr int kPreviousEndingRetrySeconds = 3;
// How long the "cannot save sessions" page asks to wait: space on a full disk comes back by a person's hand.
constexpr int kCannotRecordRetrySeconds = 60;

PageAnswer page(int status, std::string html, Headers headers = {},
                std::optional<Rejection> rejection = std::nullopt) {
  return PageAnswer{status, std::move(html), std::move(headers), rejection};
}

Headers retry_after(long long seconds) { return {{"Retry-After", std::to_string(seconds)}}; }

}  // namespace

PageAnswer answer_refused_start(const StartDecision& decision) {
  if (decision.kind == StartDecision::Kind::kRateLimited) {
    const auto seconds = decision.retry_after.count();
    return page(429, busy_page(static_cast<int>(seconds)), retry_after(seconds), Rejection::kRateLimited);
  }
  return page(decision.status, error_page(decision.status, decision.title, decision.message), {}, decision.rejection);
}

PageAnswer answer_start_outcome(const StartOutcome& outcome, const ManagerConfig& config) {
  switch (outcome.kind) {
    case StartOutcome::Kind::kJoined:
    case StartOutcome::Kind::kStarted: {
      // Behind a balancer the session's path carries this host's prefix, which routes it back here.
      const std::string location = config.public_url + config.path_prefix + "/s/" + outcome.token + "/";
      return page(302, "<!DOCTYPE html><title>Starting</title><a href=\"" + location + "\">Continue</a>\n",
                  {{"Location", location}});
    }
    case StartOutcome::Kind::kBusy: return answer_busy();
    case StartOutcome::Kind::kPreviousEnding:
      // Not the busy page and not a 503: a balancer or a participant must not take this as "try another
      // host", where a second session of the uid would start. The page reloads itself here.
      return page(409, previous_closing_page(kPreviousEndingRetrySeconds), retry_after(kPreviousEndingRetrySeconds),
                  Rejection::kBusy);
    case StartOutcome::Kind::kCompleted: return page(409, completed_page(), {}, Rejection::kCompleted);
    case StartOutcome::Kind::kTooManyUnspent: {
      // Sessions nobody opened yet end at the idle timeout, or are spent once their participant shows up.
      const auto retry = std::max<long long>(1, std::min<long long>(config.idle_timeout.count(), 60));
      return page(429, busy_page(static_cast<int>(retry)), retry_after(retry), Rejection::kUnspentLimit);
    }
    case StartOutcome::Kind::kCannotRecord:
      // Nothing started: a session the study cannot record must not run. The disk may have room again soon.
      return page(503,
                  error_page(503, "The simulation cannot start right now",
                             "The study's server cannot save new sessions at the moment. Please try the link again in "
                             "a few minutes, or tell the researcher."),
                  retry_after(kCannotRecordRetrySeconds), Rejection::kCannotRecord);
    case StartOutcome::Kind::kNoRecording:
      // No Retry-After and no reload: a recording frees up only when another watcher's session fails, and the
      // survey is told at once (outcome unavailable) so that it can go on.
      return page(503, recording_unavailable_page(outcome.uid, config.frame_origins), {}, Rejection::kNoRecording);
    case StartOutcome::Kind::kFailed: break;
  }
  return page(503, error_page(503, "The simulation could not start",
                              "Something went wrong on our side. Please try the link again in a minute, or tell "
                              "the researcher."));
}

PageAnswer answer_home_undecided() {
  return page(503, retry_later_page(kUndecidedRetrySeconds), retry_after(kUndecidedRetrySeconds), Rejection::kBusy);
}

PageAnswer answer_busy() {
  return page(503, busy_page(kBusyRetrySeconds), retry_after(kBusyRetrySeconds), Rejection::kBusy);
}

PageAnswer answer_go_home(const std::string& home, const std::string& query) {
  const std::string location = "/" + home + "/start?" + query;
  return page(303, "<!DOCTYPE html><title>Moved</title><a href=\"" + html_escape(location) + "\">Continue</a>\n",
              {{"Location", location}});
}

}  // namespace rfbsim::manager
