// SPDX-License-Identifier: GPL-2.0-or-later
#include "admin/admin_api.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "sessions/session_index.hpp"

namespace rfbsim::manager {

namespace {

// Keys stay in the order written: the admin page and operators' scripts read them, and a stable order
// makes the answers easy to compare by eye.
using Json = nlohmann::ordered_json;

// Text from a process's exit or a copy's error may hold any bytes: invalid UTF-8 is replaced, never thrown.
std::string dumped(const Json& json) { return json.dump(-1, ' ', false, Json::error_handler_t::replace); }

Json text_or_null(const std::string& text) { return text.empty() ? Json(nullptr) : Json(text); }

Json time_or_null(const std::optional<WallTime>& time) { return time ? Json(iso_utc(*time)) : Json(nullptr); }

// The stream's numbers to one decimal, as sim_rfb reports them.
Json one_decimal(const std::optional<double>& value) {
  return value ? Json(std::round(*value * 10.0) / 10.0) : Json(nullptr);
}

Json session_object(const Session& s, bool include_token) {
  Json json;
  json["id"] = s.id;
  json["uid"] = s.uid;
  json["scenario"] = s.scenario;
  json["seed"] = std::to_string(s.seed);
  json["state"] = state_name(s.state);
  json["detail"] = s.detail;
  json["exit_status"] = s.exit_status;
  json["created_at"] = iso_utc(s.created);
  json["ready_at"] = time_or_null(s.ready_at);
  json["ended_at"] = time_or_null(s.ended_at);
  json["data_path"] = s.data_path;
  json["outcome"] = text_or_null(s.outcome);
  json["copy_state"] = s.copy_state;
  json["copy_attempts"] = s.copy_attempts;
  json["copy_error"] = s.copy_error;
  // The link's parameters were stored as a JSON object by the manager itself.
  Json params = Json::parse(s.params_json.empty() ? std::string("{}") : s.params_json, nullptr, false);
  json["params"] = params.is_discarded() ? Json::object() : params;
  json["ros_namespace"] = text_or_null(s.ros_namespace);
  json["robot_control"] = text_or_null(s.robot_control);
  // The study's condition: a watcher names the session shown (by id and the keyed hash of its uid); an
  // interactive session counts the watchers holding a place with it.
  json["condition"] = s.condition;
  json["yoked_to"] = s.yoked_to > 0 ? Json(s.yoked_to) : Json(nullptr);
  json["yoked_to_uid_hash"] = text_or_null(s.yoked_to_uid_hash);
  json["watchers"] = s.watchers;
  // The stream as sim_rfb last told it; null for what it did not say and when nobody watches.
  const bool watched = s.stream && s.stream->clients > 0;
  json["codec"] = watched ? text_or_null(s.stream->codec) : Json(nullptr);
  json["rtt_ms"] = one_decimal(watched ? s.stream->rtt_ms : std::nullopt);
  json["fps"] = one_decimal(watched ? s.stream->fps : std::nullopt);
  json["quality"] = watched && s.stream->quality ? Json(*s.stream->quality) : Json(nullptr);
  if (include_token) json["token"] = s.token;
  return json;
}

Json host_entry(const std::string& id, const std::string& prefix) {
  Json json;
  json["id"] = id;
  json["prefix"] = prefix;
  return json;
}

}  // namespace

std::string admin_session_json(const Session& session, bool include_token) {
  return dumped(session_object(session, include_token));
}

std::string admin_sessions_json(int capacity, bool draining, const std::vector<Session*>& live,
                                const std::vector<Session>& recent) {
  Json json;
  json["capacity"] = capacity;
  json["draining"] = draining;
  json["live"] = Json::array();
  for (const Session* session : live) json["live"].push_back(session_object(*session, true));
  json["recent"] = Json::array();
  for (const Session& session : recent) {
    if (!is_live(session.state)) json["recent"].push_back(session_object(session, false));
  }
  return dumped(json);
}

std::string admin_host_json(const HostView& host) {
  Json json;
  json["host"] = host.host_id;
  json["prefix"] = host.path_prefix;
  json["draining"] = host.draining;
  json["shutting_down"] = host.shutting_down;
  json["live"] = host.live;
  json["max"] = host.max_sessions;
  return dumped(json);
}

std::string admin_cluster_json(const ManagerConfig& config) {
  Json json;
  json["self"] = config.host_id;
  json["prefix"] = config.path_prefix;
  json["hosts"] = Json::array();
  if (config.cluster_peers.empty()) json["hosts"].push_back(host_entry(config.host_id, config.path_prefix));
  for (const ClusterPeer& peer : config.cluster_peers) {
    const bool self_with_prefix = peer.id == config.host_id && !config.path_prefix.empty();
    json["hosts"].push_back(host_entry(peer.id, self_with_prefix ? config.path_prefix : "/" + peer.id));
  }
  return dumped(json);
}

std::string health_json(bool draining, int live_sessions, int capacity) {
  Json json;
  json["status"] = draining ? "draining" : "ok";
  json["live_sessions"] = live_sessions;
  json["capacity"] = capacity;
  return dumped(json);
}

std::string admin_error_json(const std::string& message) { return dumped(Json{{"error", message}}); }

std::string admin_ending_json(long long session_id) { return dumped(Json{{"ending", session_id}}); }

}  // namespace rfbsim::manager
