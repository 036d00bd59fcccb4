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
  kApiDrain,       ///< POST /api/drain: take no new participants (live ones go on)
  kApiUndrain,     ///< POST /api/undrain: take new participants again
  kApiHost,        ///< GET /api/host: this host's id, drain state and load, JSON
  kApiCluster,     ///< GET /api/cluster: the cluster's hosts and their path prefixes, JSON
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

/// Routes a request by method and target ("/path?query"). A path under `path_prefix` ("/h2": this manager's
/// share of a balancer's URL space, or "" for none) routes as the path without it ("/h2/s/<token>/" as
/// "/s/<token>/", "/h2" as "/"); any other path routes as it is, since the balancer sends /start and /healthz
/// unprefixed.
Route route_request(std::string_view method, std::string_view target, std::string_view path_prefix = {});

/// The path of `path` under `path_prefix`: what follows the prefix ("/" for the prefix alone), or `path` itself
/// when it does not start with "<prefix>/" (or the prefix is empty).
std::string_view strip_path_prefix(std::string_view path, std::string_view path_prefix);

/// Whether text is a valid path prefix: "/" and 1-32 of [a-z0-9-].
bool is_path_prefix(std::string_view text);

/// Whether text is a session token as the manager makes them: 32 lower-case hex digits.
bool is_token(std::string_view text);

}  // namespace rfbsim::manager
