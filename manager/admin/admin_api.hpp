// SPDX-License-Identifier: GPL-2.0-or-later
// The admin API's answers (/api/sessions, /api/host, /api/cluster, /api/drain, /api/sessions/N/end) as JSON,
// built with nlohmann::json from what the supervisor and the config say. Pure: no I/O; the HTTP layer checks
// the admin token and sends the text.
#pragma once

#include <string>
#include <vector>

#include "config/config.hpp"
#include "sessions/session.hpp"

namespace rfbsim::manager {

/// This host as the admin page and a balancer's operator see it.
struct HostView {
  std::string host_id;
  std::string path_prefix;
  bool draining = false;
  bool shutting_down = false;
  int live = 0;
  int max_sessions = 0;
};

/// One session: id, uid, scenario, seed (as text: 64 bits do not survive JavaScript's numbers), state, detail,
/// exit status, times, data path, outcome, the after-session copy ("copy_state": "" | "pending" | "done" |
/// "failed", "copy_attempts", "copy_error"), the link's parameters, the session's ROS ("ros_namespace",
/// "robot_control": text or null), and the participant's stream: "codec", "rtt_ms" and "fps" (1 decimal),
/// each null when unknown or nobody watches; the token only when `include_token` (live sessions, which a
/// researcher may watch).
std::string admin_session_json(const Session& session, bool include_token);

/// /api/sessions: capacity, drain state, the live sessions (with tokens) and the ended ones among `recent`.
std::string admin_sessions_json(int capacity, bool draining, const std::vector<Session*>& live,
                                const std::vector<Session>& recent);

/// /api/host and /api/drain's answer.
std::string admin_host_json(const HostView& host);

/// /api/cluster: this host, and each host with the path its pages have on the balancer's origin (the balancer
/// routes /<id>/ to host <id>; this host's own prefix may have been set otherwise). A single host lists itself.
std::string admin_cluster_json(const ManagerConfig& config);

/// /healthz: {"status": "ok" or "draining", "live_sessions", "capacity"}.
std::string health_json(bool draining, int live_sessions, int capacity);

/// {"error": message}.
std::string admin_error_json(const std::string& message);

/// {"ending": id}: /api/sessions/N/end accepted.
std::string admin_ending_json(long long session_id);

}  // namespace rfbsim::manager
