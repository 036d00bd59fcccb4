// SPDX-License-Identifier: GPL-2.0-or-later
// The public port's WebSocket gate, over websocketpp: which upgrades are let in (rate, address, origin, admin
// token, a live session), the relay each open socket gets, one participant browser per session (the newest
// takes over), pings for browsers that vanished, and what a browser is told when its session ends or its
// simulator goes. Included only by http/frontend.cpp (websocketpp 0.8.2 builds only as C++17).
#pragma once

#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include <websocketpp/server.hpp>

#include "admin/metrics.hpp"
#include "admission/rate_limiter.hpp"
#include "config/config.hpp"
#include "http/proxy_line.hpp"
#include "http/public_intake.hpp"
#include "http/relay.hpp"
#include "http/routes.hpp"
#include "http/web_policy.hpp"
#include "rfbsim/log.hpp"
#include "sessions/session_views.hpp"
#include "sessions/supervisor.hpp"

namespace rfbsim::manager {

/// Longer request targets are refused (414) before any parsing, on HTTP and WebSocket alike: links are short.
inline constexpr std::size_t kMaxRequestTarget = 4096;

namespace websocket_gate_detail {

// After a session's socket closes, how long to wait for the process's exit to say why, before telling the
// browser the connection was lost.
constexpr auto kUpstreamLostGrace = std::chrono::milliseconds(300);
// The close code and reason an earlier browser gets when a newer one of the same session takes over (the page
// shows it and does not reconnect by itself, or two tabs would take turns).
constexpr int kTakenOverCode = 4001;
constexpr const char* kTakenOverReason = "opened in another window";

// websocketpp's close call for a session's notice.
template <typename Connection>
void close_with(Connection& connection, SessionState state) {
  const CloseNotice notice = close_notice(state);
  websocketpp::lib::error_code ec;
  connection.close(static_cast<websocketpp::close::status::value>(notice.code), notice.reason, ec);
}

// The PROXY protocol line that tells a session which browser a relayed connection is for: the socket's peer,
// or `forwarded` (whom a trusted balancer names in X-Forwarded-For) when given. The balancer's port says
// nothing about the participant, so that line carries port 0 and an unspecified destination of the
// participant's family.
template <typename Connection>
// balancer names in X-Forwarded-For) when given. The balancer's port says nothing about the participant, so
// that line carries port 0 and an unspecified destination of the participant's family.
std::string proxy_line_for(Connection& con, const std::string& forwarded) {
  boost::system::error_code ec;
  auto& socket = con.get_raw_socket().lowest_layer();
  const auto remote = socket.remote_endpoint(ec);
  if (ec) return "PROXY UNKNOWN\r\n";
  const auto local = socket.local_endpoint(ec);
  if (ec) return "PROXY UNKNOWN\r\n";
  if (forwarded.empty()) return proxy_line(remote, local);
  const auto named = boost::asio::ip::make_address(forwarded, ec);
  if (ec) return proxy_line(remote, local);
  const boost::asio::ip::address unspecified =
      named.is_v4() ? boost::asio::ip::address(boost::asio::ip::address_v4::any())
                    : boost::asio::ip::address(boost::asio::ip::address_v6::any());
  return proxy_line({named, 0}, {unspecified, local.port()});
}

}  // namespace websocket_gate_detail

template <typename Server>
class WebSocketGate {
 public:
  using ConnectionPtr = typename Server::connection_ptr;
  using RelayT = Relay<Server>;
  using connection_hdl = websocketpp::connection_hdl;

  WebSocketGate(boost::asio::io_context& io, const ManagerConfig& config, Supervisor& supervisor, Metrics& metrics,
                Server& server, PublicIntake<Server>& intake)
      : io_(io),
        config_(config),
        supervisor_(supervisor),
        metrics_(metrics),
        server_(server),
        intake_(intake),
        upgrade_limiter_(
            {static_cast<double>(config.abuse.upgrade_per_minute), static_cast<double>(config.abuse.upgrade_burst)}),
        ping_timer_(io) {
    // A browser that stopped answering (a laptop closed, a network gone without a FIN) is found by its missing
    // pong, not after TCP's retransmissions give up many minutes later.
    if (config.abuse.ws_pong_timeout.count() > 0) {
      server_.set_pong_timeout(static_cast<long>(config.abuse.ws_pong_timeout.count()) * 1000);
      server_.set_pong_timeout_handler([this](connection_hdl hdl, std::string) {
        metrics_.count_pong_timeout();
        websocketpp::lib::error_code ec;
        auto con = server_.get_con_from_hdl(hdl, ec);
        if (!ec) con->close(websocketpp::close::status::going_away, "no answer to ping", ec);
      });
    }
  }

  /// The largest message a browser may send: what a relay holds for its session at most.
  static constexpr std::size_t kMaxMessageSize = RelayT::kMaxPending;

  /// Starts pinging open sockets (the pong timeout is websocketpp's, set by the server's owner).
  void start() {
    listening_ = true;
    ping_later();
  }

  /// Stops pinging and closes every relay with 1001.
  void stop() {
    listening_ = false;
    ping_timer_.cancel();
    auto relays = relays_;  // closing calls back into forget
    for (auto& [hdl, relay] : relays) relay->close(websocketpp::close::status::going_away, "server shutting down");
  }

  /// A message from a browser, carried to its session.
  void from_browser(connection_hdl hdl, std::string&& payload) {
    const auto it = relays_.find(hdl);
    if (it != relays_.end()) it->second->from_browser(std::move(payload));
  }

  // What the supervisor tells the frontend about a session's life.
  void session_ready(const Session& session) {
    for (auto& [hdl, relay] : relays_) {
      if (relay->session_id() == session.id) relay->connect(session.port, session.unix_socket);
    }
  }

  void session_closing(const Session& session) {
    const CloseNotice notice = close_notice(coming_state(session));
    auto relays = relays_;  // closing may call back into forget
    for (auto& [hdl, relay] : relays) {
      if (relay->session_id() == session.id) relay->close(notice);
    }
  }

  RelayCounts relay_counts() const {
    RelayCounts counts;
    for (const auto& [hdl, relay] : relays_) ++(relay->kind() == RelayKind::kWatch ? counts.watch : counts.participant);
    return counts;
  }

 private:
  // A ping to every relay's browser; the pong timeout (set above) closes those that do not answer.
  void ping_later() {
    if (config_.abuse.ws_ping_interval.count() <= 0 || config_.abuse.ws_pong_timeout.count() <= 0) return;
    ping_timer_.expires_after(config_.abuse.ws_ping_interval);
    ping_timer_.async_wait([this](const boost::system::error_code& ec) {
      if (ec || !listening_) return;
      for (const auto& entry : relays_) {
        websocketpp::lib::error_code ping_ec;
        auto con = server_.get_con_from_hdl(entry.first, ping_ec);
        if (!ping_ec && con->get_state() == websocketpp::session::state::open) con->ping("", ping_ec);
      }
      ping_later();
    });
  }

  bool reject_websocket(const ConnectionPtr& con, int status, Rejection reason, const std::string& message) {
    metrics_.count_rejection(reason);
    con->set_status(static_cast<websocketpp::http::status_code::value>(status));
    con->set_body(message + "\n");
    con->replace_header("Content-Type", "text/plain; charset=utf-8");
    return false;
  }

 public:
  /// websocketpp's validate handler: whether the upgrade may go on (else the response is set here).
  bool validate(const ConnectionPtr& con) {
    const auto decision = upgrade_limiter_.take(intake_.client_address_of(con), std::chrono::steady_clock::now());
    if (!decision.allowed) {
      con->replace_header("Retry-After", std::to_string(decision.retry_after.count()));
      return reject_websocket(con, 429, Rejection::kRateLimited, "too many connection attempts; try again later");
    }
    const std::string& target = con->get_resource();
    if (target.size() > kMaxRequestTarget) return reject_websocket(con, 414, Rejection::kBadRequest, "address too long");
    const Route route = route_request(con->get_request().get_method(), target, config_.path_prefix);
    if (route.kind != RouteKind::kSessionSocket && route.kind != RouteKind::kWatchSocket) {
      return reject_websocket(con, 404, Rejection::kBadRequest, "no WebSocket at this address");
    }
    const bool watch = route.kind == RouteKind::kWatchSocket;
    if (watch) {
      // The browser resends the admin page's Basic credentials on this handshake by itself, to any page that
      // opens the socket: the Origin check below (manager's own origin only) is what keeps other sites out.
      if (config_.admin_token.empty()) {
        return reject_websocket(con, 404, Rejection::kUnauthorized, "administration is not enabled");
      }
      if (!admin_authorized(con->get_request_header("Authorization"), config_.admin_token)) {
        con->replace_header("WWW-Authenticate", "Basic realm=\"rfbsim admin\", charset=\"UTF-8\"");
        return reject_websocket(con, 401, Rejection::kUnauthorized, "the admin token is needed");
      }
    }
    // A watcher's page is never framed by a survey, so no survey origin may open its socket either.
    if (!websocket_origin_allowed(con->get_request_header("Origin"), con->get_request_header("Host"),
                                  watch ? std::vector<std::string>{} : config_.frame_origins)) {
      return reject_websocket(con, 403, Rejection::kForbiddenOrigin, "this origin may not connect");
    }
    Session* session = supervisor_.table().by_token(route.token);
    if (session == nullptr) {
      const auto ended = supervisor_.find(route.token);
      if (ended) return reject_websocket(con, 410, Rejection::kEndedSession, "this session has ended");
      return reject_websocket(con, 404, Rejection::kUnknownSession, "no such session");
    }
    if (session->state == SessionState::kEnding) {
      return reject_websocket(con, 410, Rejection::kEndedSession, "this session has ended");
    }
    // noVNC offers "binary" when it opens the socket itself; our page offers nothing.
    for (const std::string& offered : con->get_requested_subprotocols()) {
      if (offered == "binary") {
        con->select_subprotocol(offered);
        break;
      }
    }
    pending_[con->get_handle()] = Pending{route.token, watch ? RelayKind::kWatch : RelayKind::kParticipant};
    return true;
  }

  /// websocketpp's open handler: the socket gets its relay.
  void open(connection_hdl hdl) {
    const auto pending = pending_.find(hdl);
    if (pending == pending_.end()) return;
    const std::string session_token = pending->second.token;
    const RelayKind kind = pending->second.kind;
    pending_.erase(pending);
    auto con = server_.get_con_from_hdl(hdl);
    Session* session = supervisor_.table().by_token(session_token);
    if (session == nullptr || session->state == SessionState::kEnding) {
      // It ended between the handshake's check and now: say how, as for any other ending.
      const auto ended = supervisor_.find(session_token);
      websocket_gate_detail::close_with(*con, ended ? coming_state(*ended) : SessionState::kCrashed);
      return;
    }
    // One participant browser per session: the newest wins (a refresh, a second tab, a reconnect after a blip
    // whose old socket has not timed out yet), and the earlier one is told why, so that it does not retry.
    if (kind == RelayKind::kParticipant) take_over_from_earlier(*session);
    auto relay = std::make_shared<RelayT>(server_, hdl, session->id, session->token, kind, metrics_,
                                          [this](RelayT& lost) { upstream_lost(lost); });
    if (kind == RelayKind::kParticipant) {
      relay->on_picture_delivered([this](RelayT& delivered) { supervisor_.picture_delivered(delivered.session_id()); });
    }
    relays_[hdl] = relay;
    metrics_.count_relay_open(kind);
    // Only the participant counts as connected: a researcher watching must not keep an idle session alive.
    if (kind == RelayKind::kParticipant) supervisor_.client_connected(session->id);
    // sim_rfb takes the browser's address from a PROXY line; a legacy program would take it for RFB bytes.
    // A watcher's line names no address but marks it view-only (v1 lets UNKNOWN carry that word), so that
    // sim_rfb records it as a watcher and it does not start the participant's task clock.
    if (config_.session_kind == SessionKind::kSimRfb) {
      relay->set_proxy_line(kind == RelayKind::kWatch ? std::string("PROXY UNKNOWN view-only\r\n")
                                                      : websocket_gate_detail::proxy_line_for(*con, intake_.forwarded_participant_of(con)));
    }
    if (session->state == SessionState::kRunning) relay->connect(session->port, session->unix_socket);
  }

  /// websocketpp's close and fail handlers.
  void forget(connection_hdl hdl) {
    pending_.erase(hdl);
    const auto it = relays_.find(hdl);
    if (it == relays_.end()) return;
    const auto relay = it->second;
    relays_.erase(it);
    relay->browser_gone();
    if (relay->kind() == RelayKind::kParticipant) supervisor_.client_disconnected(relay->session_id());
  }

 private:
  // Each newer browser takes over once, from the one live before it: a relay already told (and still waiting out
  // its browser's close) is not told again, nor counted, so N upgrades cost N - 1 takeovers, not N(N-1)/2.
  void take_over_from_earlier(const Session& session) {
    auto relays = relays_;  // closing calls back into forget
    for (auto& [hdl, relay] : relays) {
      if (relay->session_id() != session.id || relay->kind() != RelayKind::kParticipant || relay->closed()) continue;
      metrics_.count_takeover();
      rfbsim::log::limited(rfbsim::log::Level::kInfo, "takeover", "manager",
                           "session %lld (uid %s): a newer browser took over; the earlier one is told",
                           static_cast<long long>(session.id), session.uid.c_str());
      relay->close(static_cast<websocketpp::close::status::value>(websocket_gate_detail::kTakenOverCode), websocket_gate_detail::kTakenOverReason);
    }
  }

  // The session's socket closed under a relay. Usually the process is ending or gone, and its exit will
  // say why; give that a moment to arrive, then tell the browser what happened.
  void upstream_lost(RelayT& relay) {
    auto timer = std::make_shared<boost::asio::steady_timer>(io_, websocket_gate_detail::kUpstreamLostGrace);
    timer->async_wait([this, timer, weak = std::weak_ptr<RelayT>(relay.shared_from_this())](
                          const boost::system::error_code&) {
      const auto alive = weak.lock();
      if (!alive) return;
      const auto session = supervisor_.find(alive->token());
      if (session && session->state != SessionState::kRunning) {
        alive->close(close_notice(coming_state(*session)));
      } else {
        alive->close(websocketpp::close::status::internal_endpoint_error, "lost the connection to the simulator");
      }
    });
  }

  boost::asio::io_context& io_;
  const ManagerConfig& config_;
  Supervisor& supervisor_;
  Metrics& metrics_;
  Server& server_;
  PublicIntake<Server>& intake_;
  RateLimiter upgrade_limiter_;
  std::map<connection_hdl, std::shared_ptr<RelayT>, std::owner_less<connection_hdl>> relays_;
  // A WebSocket handshake that passed validation and has not opened yet: its session and kind.
  struct Pending {
    std::string token;
    RelayKind kind = RelayKind::kParticipant;
  };
  std::map<connection_hdl, Pending, std::owner_less<connection_hdl>> pending_;
  boost::asio::steady_timer ping_timer_;
  bool listening_ = false;
};

}  // namespace rfbsim::manager
