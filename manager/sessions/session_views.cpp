// SPDX-License-Identifier: GPL-2.0-or-later
// Sessions as browsers and the admin API see them.
#include "sessions/session_views.hpp"

#include <cstdio>

#include "sessions/session_index.hpp"
#include "http/web_policy.hpp"

namespace rfbsim::manager {

CloseNotice close_notice(SessionState state) {
  // 1000 normal closure, 1001 going away (the page shows these as an ending), 1011 an error on our side.
  switch (state) {
    case SessionState::kFinished: return {1000, "session finished"};
    case SessionState::kExpired: return {1001, "session expired"};
    case SessionState::kIdle: return {1001, "session ended after being idle"};
    case SessionState::kEnded: return {1001, "session ended by the researcher"};
    case SessionState::kShutdown: return {1001, "server shutting down"};
    case SessionState::kFailed: return {1011, "the simulator could not start"};
    default: return {1011, "the simulator stopped unexpectedly"};
  }
}

std::string status_json(const Session& session, WallTime now, const std::vector<std::string>& survey_origins,
                        const std::string& program) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", std::chrono::duration<double>(now - session.created).count());
  const auto quoted = [](const std::string& text) { return text.empty() ? std::string("null") : "\"" + json_escape(text) + "\""; };
  // A watcher's link (condition video) carries the video condition's own code as t1: given when the recording
  // was shown to its end (outcome "watched").
  const std::string& code = session.outcome == "completed" || session.outcome == "watched" ? session.code_success
                            : session.outcome == "timeout" ? session.code_timeout
                                                           : session.outcome;  // empty without an outcome
  std::string origins;
  for (const std::string& origin : survey_origins) origins += (origins.empty() ? "\"" : ",\"") + json_escape(origin) + "\"";
  return std::string("{\"state\":\"") + state_name(session.state) + "\",\"ends_as\":\"" +
         state_name(coming_state(session)) + "\",\"elapsed_s\":" + seconds + ",\"uid\":\"" + json_escape(session.uid) +
         "\",\"outcome\":" + quoted(session.outcome) + ",\"code\":" + quoted(code) + ",\"survey_origins\":[" +
         origins + "]" + (program == "sim_rfb" ? std::string() : ",\"program\":\"" + json_escape(program) + "\"") +
         (session.condition == "video" ? std::string(",\"condition\":\"video\"") : std::string()) + "}";
}

std::string session_record_json(const Session& s) {
  const auto time = [](const std::optional<WallTime>& t) { return t ? "\"" + iso_utc(*t) + "\"" : std::string("null"); };
  const auto text_or_null = [](const std::string& text) {
    return text.empty() ? std::string("null") : "\"" + json_escape(text) + "\"";
  };
  return "{\"id\":" + std::to_string(s.id) + ",\"uid\":\"" + json_escape(s.uid) + "\",\"host\":\"" +
         json_escape(s.host_id) + "\",\"address_hash\":" + text_or_null(s.address_hash) + ",\"state\":\"" +
         state_name(s.state) + "\",\"detail\":\"" + json_escape(s.detail) + "\",\"created_at\":\"" + iso_utc(s.created) +
         "\",\"ready_at\":" + time(s.ready_at) + ",\"spent_at\":" + time(s.spent_at) + ",\"ended_at\":" +
         time(s.ended_at) + ",\"outcome\":" + text_or_null(s.outcome) +
         ",\"data_incomplete\":" + text_or_null(s.data_incomplete) + ",\"ros_namespace\":" +
         text_or_null(s.ros_namespace) + ",\"robot_control\":" + text_or_null(s.robot_control) +
         ",\"condition\":\"" + json_escape(s.condition) + "\",\"yoked_to\":" +
         (s.yoked_to > 0 ? std::to_string(s.yoked_to) : std::string("null")) +
         ",\"yoked_to_uid_hash\":" + text_or_null(s.yoked_to_uid_hash) + "}\n";
}

}  // namespace rfbsim::manager
