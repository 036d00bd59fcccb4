// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's counters and their Prometheus text exposition (format 0.0.4). Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "contract/stream_line.hpp"
#include "sessions/session.hpp"

namespace rfbsim::manager {

/// Why a request was turned away; each a label value of rfbsim_rejections_total.
enum class Rejection {
  kBusy,            ///< every slot taken
  kBadRequest,      ///< a malformed or invalid parameter, path or header
  kBadSignature,    ///< signing is on and sig is missing or wrong
  kCompleted,       ///< the uid's session already ran its course
  kUnknownSession,  ///< a token that names no session
  kEndedSession,    ///< a token whose session has ended
  kForbiddenOrigin, ///< a WebSocket from an origin not allowed
  kUnauthorized,    ///< admin routes without the right token
  kStartFailed,     ///< the session program could not be started
  kRateLimited,     ///< an address over its /start or WebSocket upgrade rate (429)
  kConnectionLimit, ///< a connection over the per-address or total cap, closed at accept
  kUnspentLimit,    ///< an address that started too many sessions nobody has seen yet (429)
  kHead,            ///< a HEAD (link preview) of /start: answered, nothing started
  kCannotRecord,    ///< the session index cannot take a new session's row (a full disk): nothing started
  kNoRecording,     ///< a video-condition link found no recording it may show (503)
};

const char* rejection_name(Rejection reason);

/// Who a WebSocket relay serves; each a label value of rfbsim_relay_connections and _total.
enum class RelayKind {
  kParticipant,  ///< /s/<token>/ws: the participant, with input
  kWatch,        ///< /admin/watch/<token>/ws: a researcher, view-only
};

const char* relay_kind_name(RelayKind kind);

/// WebSocket relays open now, by kind.
struct RelayCounts {
  int participant = 0;
  int watch = 0;
};

/// One live session's stream for the per-session gauges. The label is the session's index id: a number, never
/// the uid (a participant's identity) or the token (the key to the session), which /metrics must not show.
struct SessionStream {
  std::int64_t session_id = 0;
  StreamReport report;  ///< sim_rfb's latest; sessions nobody watches (clients 0) get no series
};

/// The live sessions' streams as sim_rfb last reported them (those that reported one), for the gauges.
std::vector<SessionStream> live_streams(const std::vector<Session*>& live);

/// Counters since the manager started; the session gauges are read from the table when rendered.
class Metrics {
 public:
  /// Upper bounds of the start-up histogram's buckets, seconds.
  static constexpr std::array<double, 10> kStartupBuckets = {0.1, 0.2, 0.3, 0.5, 0.75, 1, 2, 5, 10, 30};

  void count_start() { ++starts_; }
  void count_rejection(Rejection reason) { ++rejections_[reason]; }
  /// A session became ready `seconds` after /start accepted it.
  void observe_startup(double seconds);
  void add_bytes_to_client(std::uint64_t bytes) { bytes_to_client_ += bytes; }
  void add_bytes_to_session(std::uint64_t bytes) { bytes_to_session_ += bytes; }
  void count_relay_open(RelayKind kind) { ++relays_opened_[kind == RelayKind::kWatch ? 1 : 0]; }
  /// A participant's second browser took the session over from the first.
  void count_takeover() { ++takeovers_; }
  /// A WebSocket closed because its pong did not come back in time.
  void count_pong_timeout() { ++pong_timeouts_; }
  /// accept() failed (e.g. EMFILE: no descriptor left) and accepting paused for a moment.
  void count_accept_error() { ++accept_errors_; }
  /// A write of the session index (or a session's manager.json) failed; it is kept and tried again.
  void count_index_write_error() { ++index_write_errors_; }
  /// Gauges of the public port's connections, set by the frontend before rendering.
  void set_connections(std::size_t open, std::size_t addresses) {
    connections_open_ = open;
    connection_addresses_ = addresses;
  }

  [[nodiscard]] std::uint64_t starts() const { return starts_; }
  [[nodiscard]] std::uint64_t rejections(Rejection reason) const;
  [[nodiscard]] std::uint64_t bytes_to_client() const { return bytes_to_client_; }
  [[nodiscard]] std::uint64_t takeovers() const { return takeovers_; }
  [[nodiscard]] std::uint64_t index_write_errors() const { return index_write_errors_; }

  /// The exposition text. `sessions_by_state`: live sessions by state now, and ended ones by state over
  /// the whole index; `relays`: WebSocket relays open now; `streams`: live sessions' streams, for
  /// rfbsim_session_rtt_ms, rfbsim_session_fps, rfbsim_session_quality and rfbsim_session_codec_info (each series only where known).
  [[nodiscard]] std::string render(const std::map<SessionState, std::int64_t>& sessions_by_state, int capacity,
                                   RelayCounts relays, const std::vector<SessionStream>& streams = {}) const;

 private:
  std::uint64_t starts_ = 0;
  std::map<Rejection, std::uint64_t> rejections_;
  std::array<std::uint64_t, kStartupBuckets.size()> startup_buckets_{};
  std::uint64_t startup_count_ = 0;
  double startup_sum_ = 0;
  std::uint64_t bytes_to_client_ = 0;
  std::uint64_t bytes_to_session_ = 0;
  std::array<std::uint64_t, 2> relays_opened_{};  // participant, watch
  std::uint64_t takeovers_ = 0;
  std::uint64_t pong_timeouts_ = 0;
  std::uint64_t accept_errors_ = 0;
  std::uint64_t index_write_errors_ = 0;
  std::size_t connections_open_ = 0;
  std::size_t connection_addresses_ = 0;
};

}  // namespace rfbsim::manager
