// SPDX-License-Identifier: GPL-2.0-or-later
// The small HTML pages the manager answers with itself: home, busy, already completed, session ended and
// errors. Written for participants (plain words, no jargon) and safe to show in a survey iframe. Pure.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::manager {

/// GET /: what this server is.
std::string home_page();

/// Every simulator is busy: the page reloads itself (retrying the same link) after `retry_seconds`.
std::string busy_page(int retry_seconds);

/// Too few hosts of a cluster answered to decide where the uid's session runs: the page reloads itself
/// (retrying the same link) after `retry_seconds`.
std::string retry_later_page(int retry_seconds);

/// The uid's own earlier session is still closing: the page reloads itself after `retry_seconds`. Not the
/// busy page: nothing else is wrong, and the participant must come back to this host.
std::string previous_closing_page(int retry_seconds);

/// The uid's session already ran its course.
std::string completed_page();

/// The session behind a link has ended (`state` in words, e.g. "expired").
std::string session_ended_page(std::string_view state);

/// A video-condition link with no recording free to show (503). Inside a survey's frame the page tells the
/// survey, as the participant's page does an outcome: {type: "rfbsim", event, uid, code: null, outcome:
/// "unavailable"}, event "unavailable" then "ended", posted to the parent only at `survey_origins` (the
/// manager's frame_origins), so that a page framed by anyone else hears nothing.
std::string recording_unavailable_page(std::string_view uid, const std::vector<std::string>& survey_origins);

/// Any other refusal: a title and a message (escaped here).
std::string error_page(int status, std::string_view title, std::string_view message);

}  // namespace rfbsim::manager
