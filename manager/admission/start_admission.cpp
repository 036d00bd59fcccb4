// SPDX-License-Identifier: GPL-2.0-or-later
#include "admission/start_admission.hpp"

#include "admission/link_signature.hpp"
#include "http/query.hpp"
#include "sessions/launch_plan.hpp"

namespace rfbsim::manager {

namespace {

StartDecision refused(int status, Rejection rejection, std::string title, std::string message) {
  StartDecision decision;
  decision.kind = StartDecision::Kind::kRefused;
  decision.status = status;
  decision.rejection = rejection;
  decision.title = std::move(title);
  decision.message = std::move(message);
  return decision;
}

StartDecision invalid_link(int status, Rejection rejection, std::string message) {
  return refused(status, rejection, "This link is not valid", std::move(message));
}

}  // namespace

StartAdmission::StartAdmission(const ManagerConfig& config)
    : config_(config),
      limiter_({static_cast<double>(config.abuse.start_per_minute), static_cast<double>(config.abuse.start_burst)}) {}

StartDecision StartAdmission::decide(const std::string& query, const std::string& address,
                                     std::chrono::steady_clock::time_point now, long long unix_now) {
  const auto rate = limiter_.take(address, now);
  if (!rate.allowed) {
    StartDecision decision;
    decision.kind = StartDecision::Kind::kRateLimited;
    decision.retry_after = rate.retry_after;
    return decision;
  }
  std::string error;
  const auto params = parse_query(query, error);
  if (!params) return invalid_link(400, Rejection::kBadRequest, error);
  // The signature before anything else, so that unsigned links learn nothing about valid parameters.
  if (!config_.link_secret.empty() && !link_signature_valid(*params, config_.link_secret)) {
    return invalid_link(403, Rejection::kBadSignature,
                        "The link's signature is missing or wrong. Please use the exact link your survey gave you.");
  }
  StartParse parsed = parse_start_request(*params, scenario_names(config_.scenarios), config_.scenario_facts);
  if (!parsed.request) return invalid_link(400, Rejection::kBadRequest, parsed.error);
  if (std::string problem = ros_request_problem(config_, *parsed.request); !problem.empty()) {
    return invalid_link(400, Rejection::kBadRequest, std::move(problem));
  }
  // A study may fix the view for everyone: then a link that chooses one is refused, not silently overruled.
  if (!config_.allow_camera_param) {
    for (const auto& [name, value] : parsed.request->overrides) {
      if (name != "camera") continue;
      return invalid_link(400, Rejection::kBadRequest,
                          "camera is not offered here: this study's sessions all have their scenario's view "
                          "(allow_camera_param is off)");
    }
  }
  // The video condition replays sim_rfb's recordings; a pinned source is the researcher's choice, so only a
  // signed link may make it (a participant editing an unsigned link could pick whom they watch).
  if (parsed.request->condition == "video" && config_.session_kind != SessionKind::kSimRfb) {
    return invalid_link(400, Rejection::kBadRequest,
                        "condition video is not offered here: only sim_rfb sessions are recorded to be replayed");
  }
  if (!parsed.request->yoke_uid.empty() && config_.link_secret.empty()) {
    return invalid_link(400, Rejection::kBadRequest,
                        "yoke_uid is offered only on signed links (link_secret), so that a participant cannot choose "
                        "whom they watch");
  }
  // A link published in the open can be given an end: exp, a Unix time, signed with the rest.
  if (config_.require_link_expiry && !parsed.request->expires_at) {
    return invalid_link(403, Rejection::kBadSignature,
                        "The link has no expiry time. Please use the exact link your survey gave you.");
  }
  if (parsed.request->expires_at && unix_now >= 0 &&
      *parsed.request->expires_at < static_cast<std::uint64_t>(unix_now)) {
    return refused(410, Rejection::kBadSignature, "This link has expired",
                   "The study link is no longer valid. Please go back to the survey or contact the researcher.");
  }
  StartDecision decision;
  decision.kind = StartDecision::Kind::kAdmitted;
  decision.request = std::move(parsed.request);
  return decision;
}

}  // namespace rfbsim::manager
