// SPDX-License-Identifier: GPL-2.0-or-later
// How a session is shown outside the manager: the close code and reason its browsers get, the JSON of the
// page's status poll and of the admin API. Pure: no I/O.
#pragma once

#include <string>
#include <vector>

#include "sessions/session.hpp"

namespace rfbsim::manager {

/// A WebSocket close: RFC 6455 status code and a reason the page can show.
struct CloseNotice {
  int code = 1000;
  std::string reason;
};

/// What a browser is told when its session closes, by the state the session has or is ending into.
CloseNotice close_notice(SessionState state);

/// The page's poll (/s/<token>/status): {"state":..., "ends_as":..., "elapsed_s": seconds since /start,
/// 3 decimals, "uid":..., "outcome": "completed" | "timeout" | null, "code": the outcome's completion code
/// or null, "survey_origins": [...]}. The page posts the outcome to its parent window, and only to
/// `survey_origins` (a watching researcher's page gets none). A session of another program than sim_rfb adds
/// "program": `program` ("rfb" or "x11", session_kind_name), so that the page does not offer sim_rfb's WASD hint;
/// "condition": "video" (only then) tells the page that its participant watches a recording.
std::string status_json(const Session& session, WallTime now, const std::vector<std::string>& survey_origins,
                        const std::string& program = "sim_rfb");

/// The manager's record of a session, written beside the session's own data as manager.json so that the
/// study's tools (sim_report) see how each session ended without the index: {"id", "uid", "host",
/// "address_hash", "state", "detail", "created_at", "ready_at", "spent_at", "ended_at", "outcome",
/// "data_incomplete", "ros_namespace", "robot_control", "condition", "yoked_to", "yoked_to_uid_hash"} (times ISO
/// 8601 UTC or null; address_hash, outcome, data_incomplete, ros_namespace, robot_control, yoked_to and
/// yoked_to_uid_hash null when there is none; condition "interactive" or "video"). address_hash is the participant's address hashed as in events.jsonl. No token, address or secret.
std::string session_record_json(const Session& session);

}  // namespace rfbsim::manager
