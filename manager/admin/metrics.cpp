// SPDX-License-Identifier: GPL-2.0-or-later
// Prometheus text for the manager's counters.
#include "admin/metrics.hpp"

#include <cstdio>

namespace rfbsim::manager {

namespace {

constexpr Rejection kAllRejections[] = {
    Rejection::kBusy,           Rejection::kBadRequest,   Rejection::kBadSignature,
    Rejection::kCompleted,      Rejection::kUnknownSession, Rejection::kEndedSession,
    Rejection::kForbiddenOrigin, Rejection::kUnauthorized, Rejection::kStartFailed,
    Rejection::kRateLimited,    Rejection::kConnectionLimit, Rejection::kUnspentLimit,
    Rejection::kHead,           Rejection::kCannotRecord,   Rejection::kNoRecording};

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

void header(std::string& out, const char* name, const char* type, const char* help) {
  out += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
}

// A label value as the exposition format quotes it: backslash, double quote and newline escaped. The values
// used are plain already (state names, numbers, codec names the stream parser checked); this keeps any other
// from breaking the text.
std::string label_value(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

const char* rejection_name(Rejection reason) {
  switch (reason) {
    case Rejection::kBusy: return "busy";
    case Rejection::kBadRequest: return "bad_request";
    case Rejection::kBadSignature: return "bad_signature";
    case Rejection::kCompleted: return "already_completed";
    case Rejection::kUnknownSession: return "unknown_session";
    case Rejection::kEndedSession: return "ended_session";
    case Rejection::kForbiddenOrigin: return "forbidden_origin";
    case Rejection::kUnauthorized: return "unauthorized";
    case Rejection::kStartFailed: return "start_failed";
    case Rejection::kRateLimited: return "rate_limited";
    case Rejection::kConnectionLimit: return "connection_limit";
    case Rejection::kUnspentLimit: return "unspent_limit";
    case Rejection::kHead: return "head_preview";
    case Rejection::kCannotRecord: return "cannot_record";
    case Rejection::kNoRecording: return "no_recording";
  }
  return "other";
}

const char* relay_kind_name(RelayKind kind) { return kind == RelayKind::kWatch ? "watch" : "participant"; }

void Metrics::observe_startup(double seconds) {
  ++startup_count_;
  startup_sum_ += seconds;
  for (std::size_t i = 0; i < kStartupBuckets.size(); ++i) {
    if (seconds <= kStartupBuckets[i]) ++startup_buckets_[i];
  }
}

std::uint64_t Metrics::rejections(Rejection reason) const {
  const auto it = rejections_.find(reason);
  return it == rejections_.end() ? 0 : it->second;
}

std::string Metrics::render(const std::map<SessionState, std::int64_t>& sessions_by_state, int capacity,
                            RelayCounts relays, const std::vector<SessionStream>& streams) const {
  std::string out;
  header(out, "rfbsim_sessions", "gauge", "Sessions by state (live states now; ended states in the whole index).");
  for (const SessionState state : kAllStates) {
    const auto it = sessions_by_state.find(state);
    out += std::string("rfbsim_sessions{state=\"") + state_name(state) + "\"} " +
           std::to_string(it == sessions_by_state.end() ? 0 : it->second) + "\n";
  }
  header(out, "rfbsim_session_capacity", "gauge", "Live sessions allowed at once.");
  out += "rfbsim_session_capacity " + std::to_string(capacity) + "\n";
  header(out, "rfbsim_session_starts_total", "counter", "Sessions started since the manager started.");
  out += "rfbsim_session_starts_total " + std::to_string(starts_) + "\n";
  header(out, "rfbsim_session_startup_seconds", "histogram", "Time from /start to the session being ready.");
  for (std::size_t i = 0; i < kStartupBuckets.size(); ++i) {
    out += "rfbsim_session_startup_seconds_bucket{le=\"" + number(kStartupBuckets[i]) + "\"} " +
           std::to_string(startup_buckets_[i]) + "\n";
  }
  out += "rfbsim_session_startup_seconds_bucket{le=\"+Inf\"} " + std::to_string(startup_count_) + "\n";
  out += "rfbsim_session_startup_seconds_sum " + number(startup_sum_) + "\n";
  out += "rfbsim_session_startup_seconds_count " + std::to_string(startup_count_) + "\n";
  header(out, "rfbsim_relay_bytes_total", "counter", "Bytes relayed between browsers and sessions.");
  out += "rfbsim_relay_bytes_total{direction=\"to_client\"} " + std::to_string(bytes_to_client_) + "\n";
  out += "rfbsim_relay_bytes_total{direction=\"to_session\"} " + std::to_string(bytes_to_session_) + "\n";
  // By kind: a researcher watching is no participant, and dashboards should not count one as such.
  constexpr RelayKind kKinds[] = {RelayKind::kParticipant, RelayKind::kWatch};
  header(out, "rfbsim_relay_connections", "gauge", "WebSocket relays open now, by kind (participant or watch).");
  for (const RelayKind kind : kKinds) {
    out += std::string("rfbsim_relay_connections{kind=\"") + relay_kind_name(kind) + "\"} " +
           std::to_string(kind == RelayKind::kWatch ? relays.watch : relays.participant) + "\n";
  }
  header(out, "rfbsim_relay_connections_total", "counter",
         "WebSocket relays opened since the manager started, by kind (participant or watch).");
  for (const RelayKind kind : kKinds) {
    out += std::string("rfbsim_relay_connections_total{kind=\"") + relay_kind_name(kind) + "\"} " +
           std::to_string(relays_opened_[kind == RelayKind::kWatch ? 1 : 0]) + "\n";
  }
  header(out, "rfbsim_rejections_total", "counter", "Requests turned away, by reason.");
  for (const Rejection reason : kAllRejections) {
    out += std::string("rfbsim_rejections_total{reason=\"") + rejection_name(reason) + "\"} " +
           std::to_string(rejections(reason)) + "\n";
  }
  header(out, "rfbsim_takeovers_total", "counter",
         "Participant connections replaced by a newer browser of the same session (a refresh, a second tab).");
  out += "rfbsim_takeovers_total " + std::to_string(takeovers_) + "\n";
  header(out, "rfbsim_pong_timeouts_total", "counter", "WebSockets closed because their pong came too late.");
  out += "rfbsim_pong_timeouts_total " + std::to_string(pong_timeouts_) + "\n";
  header(out, "rfbsim_accept_errors_total", "counter",
         "Failed accepts on the public port (EMFILE: out of descriptors), each followed by a short pause.");
  out += "rfbsim_accept_errors_total " + std::to_string(accept_errors_) + "\n";
  header(out, "rfbsim_index_write_errors_total", "counter",
         "Failed writes of the session index or a session's manager.json (a full disk); each is kept and retried.");
  out += "rfbsim_index_write_errors_total " + std::to_string(index_write_errors_) + "\n";
  header(out, "rfbsim_connections", "gauge", "Connections open on the public port now.");
  out += "rfbsim_connections " + std::to_string(connections_open_) + "\n";
  header(out, "rfbsim_connection_addresses", "gauge", "Client addresses with a connection open now.");
  out += "rfbsim_connection_addresses " + std::to_string(connection_addresses_) + "\n";
  // Each watched session's stream, as sim_rfb last reported it (about every second).
  const auto session_label = [](const SessionStream& s) { return "session=\"" + std::to_string(s.session_id) + "\""; };
  header(out, "rfbsim_session_rtt_ms", "gauge",
         "The participant's latest round trip through the session's picture stream, ms (fences; where measured).");
  for (const SessionStream& s : streams) {
    if (s.report.clients > 0 && s.report.rtt_ms) {
      out += "rfbsim_session_rtt_ms{" + session_label(s) + "} " + number(*s.report.rtt_ms) + "\n";
    }
  }
  header(out, "rfbsim_session_fps", "gauge", "Picture updates per second to the session's participant, lately.");
  for (const SessionStream& s : streams) {
    if (s.report.clients > 0 && s.report.fps) {
      out += "rfbsim_session_fps{" + session_label(s) + "} " + number(*s.report.fps) + "\n";
    }
  }
  header(out, "rfbsim_session_quality", "gauge",
         "The JPEG quality of the session's picture stream now (Tight), or the configured level (H.264).");
  for (const SessionStream& s : streams) {
    if (s.report.clients > 0 && s.report.quality) {
      out += "rfbsim_session_quality{" + session_label(s) + "} " + std::to_string(*s.report.quality) + "\n";
    }
  }
  header(out, "rfbsim_session_codec_info", "gauge", "The encoding of the session's picture stream (tight, h264, zrle, hextile, raw ...): 1.");
  for (const SessionStream& s : streams) {
    if (s.report.clients > 0 && !s.report.codec.empty()) {
      out += "rfbsim_session_codec_info{" + session_label(s) + ",codec=\"" + label_value(s.report.codec) + "\"} 1\n";
    }
  }
  return out;
}

std::vector<SessionStream> live_streams(const std::vector<Session*>& live) {
  std::vector<SessionStream> streams;
  for (const Session* session : live) {
    if (session->stream) streams.push_back({session->id, *session->stream});
  }
  return streams;
}

}  // namespace rfbsim::manager
