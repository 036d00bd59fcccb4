// SPDX-License-Identifier: GPL-2.0-or-later
// Routing of sim_manager's one port: which handler a request target belongs to. Pure: no I/O.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace rfbsim::manager {

enum class RouteKind {
  kHome,           ///< GET /
  kStart,          ///< GET /start?...
  kSessionFile,    ///< GET /s/<token>/<file>: the participant page and its scripts ("" = index.html)
  kSessionStatus,  ///< GET /s/<token>/status: start-up progress for the page, JSON
  kSessionSocket,  ///< GET /s/<token>/ws (WebSocket upgrade): the relay
  kHealth,         ///< GET /healthz
  kMetrics,        ///< GET /metrics
  kAdminPage,      ///< GET /admin (and its script)
  kWatchFile,      ///< GET /admin/watch/<token>/<file>: the participant page, for a researcher to watch
  kWatchStatus,    ///< GET /admin/watch/<token>/status: as kSessionStatus
  kWatchSocket,    ///< GET /admin/watch/<token>/ws (WebSocket upgrade): the view-only relay
  kApiSessions,    ///< GET /api/sessions
  kApiEndSession,  ///< POST /api/sessions/<id>/end
  kNotFound,
  kBadMethod,      ///< a known path with a method it does not take
};

/// A routed request: what it is for and the parts of the path it names.
struct Route {
  RouteKind kind = RouteKind::kNotFound;
  std::string token;      ///< kSession*, kWatch*: 32 lower-case hex digits (checked)
  std::string file;       ///< kSessionFile, kWatchFile, kAdminPage: the rest of the path after the prefix (not
                          ///< decoded)
  std::int64_t session_id = 0;  ///< kApiEndSession
  std::string query;      ///< the raw query string (after '?')
  const char* allowed = "GET, HEAD";  ///< kBadMethod: the methods the path takes (an Allow header)
};

/// Routes a request by method and target ("/path?query").
Route route_request(std::string_view method, std::string_view target);

/// Whether text is a session token as the manager makes them: 32 lower-case hex digits.
bool is_token(std::string_view text);

}  // namespace rfbsim::manager
