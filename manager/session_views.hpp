// SPDX-License-Identifier: GPL-2.0-or-later
// How a session is shown outside the manager: the close code and reason its browsers get, the JSON of the
// page's status poll and of the admin API. Pure: no I/O.
#pragma once

#include <string>

#include "session.hpp"

namespace rfbsim::manager {

/// A WebSocket close: RFC 6455 status code and a reason the page can show.
struct CloseNotice {
  int code = 1000;
  std::string reason;
};

/// What a browser is told when its session closes, by the state the session has or is ending into.
CloseNotice close_notice(SessionState state);

/// The page's start-up poll (/s/<token>/status): {"state":..., "ends_as":..., "elapsed_s": seconds since
/// /start, 3 decimals}.
std::string status_json(const Session& session, WallTime now);

/// One session for the admin API: id, uid, scenario, seed, state, detail, exit status, times, data path and
/// the link's parameters; the token only when `include_token` (live sessions, which a researcher may watch).
std::string session_json(const Session& session, bool include_token);

}  // namespace rfbsim::manager
