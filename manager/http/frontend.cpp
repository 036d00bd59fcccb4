// SPDX-License-Identifier: GPL-2.0-or-later
// The public port on websocketpp: routes HTTP requests to their handlers and WebSockets to relays.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "http/frontend.hpp"

#include <algorithm>
#include <boost/asio/ssl/context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/server.hpp>

#include "sessions/launch_plan.hpp"
#include "admission/link_signature.hpp"
#include "http/pages.hpp"
#include "http/proxy_line.hpp"
#include "http/public_intake.hpp"
#include "http/query.hpp"
#include "admission/rate_limiter.hpp"
#include "cluster/registry_client.hpp"
#include "http/relay.hpp"
#include "http/routes.hpp"
#include "sessions/session_views.hpp"
#include "admission/start_request.hpp"
#include "static_files.hpp"
#include "admission/unix_time.hpp"
#include "http/web_policy.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using websocketpp::connection_hdl;
using CloseCode = websocketpp::close::status::value;

// Longer request targets are refused (414) before any parsing: links are short.
constexpr std::size_t kMaxTarget = 4096;
// How long the busy page waits before it tries the link again.
constexpr int kBusyRetrySeconds = 10;
// How long the "try again in a moment" page waits when too few hosts answered to decide a uid's home.
constexpr int kUndecidedRetrySeconds = 5;
// How long the "previous session is closing" page waits: an ending session is gone within the stop grace.
constexpr int kPreviousEndingRetrySeconds = 3;
// How many ended sessions the admin API lists besides the live ones.
constexpr int kAdminRecentSessions = 200;
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
  connection.close(static_cast<CloseCode>(notice.code), notice.reason, ec);
}

// The PROXY protocol line that tells a session which browser a relayed connection is for.
template <typename Connection>
// The PROXY line naming the browser to the session: the socket's peer, or `forwarded` (whom a trusted
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

std::string read_file(const std::filesystem::path& path, bool& ok) {
  std::ifstream in(path, std::ios::binary);
  ok = static_cast<bool>(in) && std::filesystem::is_regular_file(path);
  if (!ok) return "";
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

template <typename WsConfig>
class FrontendImpl final : public Frontend, public SessionListener {
 public:
  using Server = websocketpp::server<WsConfig>;
  using ConnectionPtr = typename Server::connection_ptr;
  using RelayT = Relay<Server>;

  FrontendImpl(asio::io_context& io, const ManagerConfig& config, Supervisor& supervisor, Metrics& metrics,
               std::string web_root, bool tls, RegistryClient* registry)
      : io_(io),
        config_(config),
        supervisor_(supervisor),
        metrics_(metrics),
        web_root_(std::move(web_root)),
        tls_(tls),
        registry_(registry),
        start_limiter_({static_cast<double>(config.abuse.start_per_minute), static_cast<double>(config.abuse.start_burst)}),
        upgrade_limiter_(
            {static_cast<double>(config.abuse.upgrade_per_minute), static_cast<double>(config.abuse.upgrade_burst)}),
        intake_(io, server_, config, metrics),
        ping_timer_(io) {
    server_.clear_access_channels(websocketpp::log::alevel::all);
    server_.clear_error_channels(websocketpp::log::elevel::all);
    server_.init_asio(&io_);
    server_.set_user_agent("rfbsim-manager");
    server_.set_reuse_addr(true);
    server_.set_listen_backlog(256);
    server_.set_open_handshake_timeout(5000);   // a slow or silent client loses its connection, not ours
    server_.set_close_handshake_timeout(2000);
    server_.set_max_http_body_size(64 * 1024);
    server_.set_max_message_size(RelayT::kMaxPending);
    // No Nagle on browser sockets: the relay sends each update's last small piece as it comes, and with
    // Nagle it waited for the browser's delayed ACK (about 50 ms per update, measured by bench_manager).
    // (After accept: websocketpp's socket-init hook runs before the socket is open.)
    server_.set_tcp_pre_init_handler([this](connection_hdl hdl) {
      boost::system::error_code ignored;
      server_.get_con_from_hdl(hdl)->get_raw_socket().set_option(asio::ip::tcp::no_delay(true), ignored);
    });
    // No exception leaves a handler: a request that trips one costs its own connection, never the I/O loop
    // that carries every session.
    server_.set_http_handler([this](connection_hdl hdl) {
      guarded("an HTTP request", hdl, [&] { handle_http(server_.get_con_from_hdl(hdl)); });
    });
    server_.set_validate_handler([this](connection_hdl hdl) {
      bool accepted = false;
      guarded("a WebSocket handshake", hdl, [&] { accepted = validate_websocket(server_.get_con_from_hdl(hdl)); });
      return accepted;
    });
    server_.set_open_handler([this](connection_hdl hdl) { guarded("a WebSocket", hdl, [&] { open_websocket(hdl); }); });
    server_.set_close_handler([this](connection_hdl hdl) { forget_websocket(hdl); });
    server_.set_fail_handler([this](connection_hdl hdl) { forget_websocket(hdl); });
    server_.set_message_handler([this](connection_hdl hdl, typename Server::message_ptr message) {
      const auto it = relays_.find(hdl);
      if (it != relays_.end()) it->second->from_browser(std::move(message->get_raw_payload()));
    });
    // A browser that stopped answering (a laptop closed, a network gone without a FIN) is found by its missing
    // pong, not after TCP's retransmissions give up many minutes later.
    if (config_.abuse.ws_pong_timeout.count() > 0) {
      server_.set_pong_timeout(static_cast<long>(config_.abuse.ws_pong_timeout.count()) * 1000);
      server_.set_pong_timeout_handler([this](connection_hdl hdl, std::string) {
        metrics_.count_pong_timeout();
        websocketpp::lib::error_code ec;
        auto con = server_.get_con_from_hdl(hdl, ec);
        if (!ec) con->close(websocketpp::close::status::going_away, "no answer to ping", ec);
      });
    }
    supervisor_.set_listener(this);
  }

  ~FrontendImpl() override { supervisor_.set_listener(nullptr); }

  Server& server() { return server_; }

  void listen() {
    websocketpp::lib::error_code ec;
    boost::system::error_code address_ec;
    const auto address = asio::ip::make_address_v4(config_.listen_address, address_ec);
    if (address_ec) throw std::runtime_error("bad listen address " + config_.listen_address);
    server_.listen(asio::ip::tcp::endpoint(address, static_cast<unsigned short>(config_.port)), ec);
    if (ec) {
      throw std::runtime_error("cannot listen on " + config_.listen_address + ":" + std::to_string(config_.port) +
                               ": " + ec.message());
    }
    listening_ = true;
    intake_.start();
    ping_relays_later();
  }

  int port() const override {
    boost::system::error_code ec;
    const auto endpoint = const_cast<Server&>(server_).get_local_endpoint(ec);
    return ec ? 0 : endpoint.port();
  }
  const char* scheme() const override { return tls_ ? "https" : "http"; }

  void stop() override {
    websocketpp::lib::error_code ec;
    listening_ = false;
    intake_.stop();
    ping_timer_.cancel();
    server_.stop_listening(ec);
    auto relays = relays_;
    for (auto& [hdl, relay] : relays) relay->close(websocketpp::close::status::going_away, "server shutting down");
  }

  // A ping to every relay's browser; the pong timeout (set above) closes those that do not answer.
  void ping_relays_later() {
    if (config_.abuse.ws_ping_interval.count() <= 0 || config_.abuse.ws_pong_timeout.count() <= 0) return;
    ping_timer_.expires_after(config_.abuse.ws_ping_interval);
    ping_timer_.async_wait([this](const boost::system::error_code& ec) {
      if (ec || !listening_) return;
      for (const auto& entry : relays_) {
        websocketpp::lib::error_code ping_ec;
        auto con = server_.get_con_from_hdl(entry.first, ping_ec);
        if (!ping_ec && con->get_state() == websocketpp::session::state::open) con->ping("", ping_ec);
      }
      ping_relays_later();
    });
  }

  // Runs `work` for connection `hdl`; an exception is logged and ends that connection only.
  template <typename Work>
  void guarded(const char* what, connection_hdl hdl, Work&& work) {
    try {
      work();
    } catch (const std::exception& error) {
      std::fprintf(stderr, "[manager] %s failed: %s; its connection is closed\n", what, error.what());
      websocketpp::lib::error_code ec;
      auto con = server_.get_con_from_hdl(hdl, ec);
      if (!ec) con->terminate(ec);
    }
  }

  // SessionListener
  void session_ready(const Session& session) override {
    for (auto& [hdl, relay] : relays_) {
      if (relay->session_id() == session.id) relay->connect(session.port, session.unix_socket);
    }
  }

  void session_closing(const Session& session) override {
    const CloseNotice notice = close_notice(coming_state(session));
    auto relays = relays_;  // closing may call back into forget_websocket
    for (auto& [hdl, relay] : relays) {
      if (relay->session_id() == session.id) relay->close(notice);
    }
  }

 private:
  // ------------------------------------------------------------------------------------------------------
  // HTTP
  // ------------------------------------------------------------------------------------------------------
  void respond(const ConnectionPtr& con, int status, const std::string& body, const std::string& content_type,
               const Headers& extra = {}) {
    con->set_status(static_cast<websocketpp::http::status_code::value>(status));
    con->set_body(body);
    con->replace_header("Content-Type", content_type);
    con->replace_header("Cache-Control", "no-store");
    // websocketpp closes the connection after every plain HTTP response; say so, or a client that keeps
    // connections alive (Node's fetch, some proxies) may send its next request down a closed socket.
    con->replace_header("Connection", "close");
    for (const auto& [name, value] : extra) con->replace_header(name, value);
  }

  void respond_page(const ConnectionPtr& con, int status, const std::string& html, Headers extra = {}) {
    Headers headers = page_headers(config_.frame_origins);
    headers.insert(headers.end(), extra.begin(), extra.end());
    respond(con, status, html, "text/html; charset=utf-8", headers);
  }

  void respond_json(const ConnectionPtr& con, int status, const std::string& json) {
    respond(con, status, json, "application/json");
  }

  void refuse(const ConnectionPtr& con, int status, Rejection reason, const std::string& title,
              const std::string& message) {
    metrics_.count_rejection(reason);
    respond_page(con, status, error_page(status, title, message));
  }

  void handle_http(const ConnectionPtr& con) {
    const std::string& target = con->get_resource();
    if (target.size() > kMaxTarget) {
      refuse(con, 414, Rejection::kBadRequest, "Link too long", "The address is too long to be a study link.");
      return;
    }
    const Route route = route_request(con->get_request().get_method(), target, config_.path_prefix);
    switch (route.kind) {
      case RouteKind::kHome: respond_page(con, 200, home_page()); return;
      case RouteKind::kStart:
        // A HEAD (link previews, mail scanners) learns that the link exists and starts nothing.
        if (con->get_request().get_method() == "HEAD") {
          metrics_.count_rejection(Rejection::kHead);
          respond(con, 200, "", "text/html; charset=utf-8", page_headers(config_.frame_origins));
          return;
        }
        handle_start(con, route);
        return;
      case RouteKind::kSessionFile: handle_session_file(con, route, page_headers(config_.frame_origins)); return;
      case RouteKind::kSessionStatus: handle_session_status(con, route, config_.frame_origins); return;
      case RouteKind::kSessionSocket:
        refuse(con, 400, Rejection::kBadRequest, "WebSocket only", "This address takes WebSocket connections only.");
        return;
      // The researcher's view of a session: the participant's page behind the admin token, framed by no
      // survey (a survey page must not show a researcher's view), its socket relayed view-only.
      case RouteKind::kWatchFile:
        if (admin_allowed(con)) handle_session_file(con, route, page_headers({}));
        return;
      case RouteKind::kWatchStatus:
        if (admin_allowed(con)) handle_session_status(con, route, {});
        return;
      case RouteKind::kWatchSocket:
        if (admin_allowed(con)) {
          refuse(con, 400, Rejection::kBadRequest, "WebSocket only", "This address takes WebSocket connections only.");
        }
        return;
      case RouteKind::kHealth: {
        // A balancer's health check takes a draining or stopping host out of its pool for new participants;
        // the host's own backend (no health check on it) still reaches its live sessions.
        const bool draining = supervisor_.draining() || supervisor_.shutting_down();
        respond_json(con, draining ? 503 : 200,
                     std::string("{\"status\":\"") + (draining ? "draining" : "ok") + "\",\"live_sessions\":" +
                         std::to_string(supervisor_.table().size()) + ",\"capacity\":" +
                         std::to_string(config_.max_sessions) + "}");
        return;
      }
      case RouteKind::kMetrics:
        metrics_.set_connections(intake_.open_total(), intake_.addresses());
        respond(con, 200,
                metrics_.render(supervisor_.counts_by_state(), config_.max_sessions, relay_counts(), session_streams()),
                "text/plain; version=0.0.4; charset=utf-8");
        return;
      case RouteKind::kAdminPage: handle_admin_page(con, route); return;
      case RouteKind::kApiSessions: handle_api_sessions(con); return;
      case RouteKind::kApiEndSession: handle_api_end(con, route); return;
      case RouteKind::kApiDrain: handle_api_drain(con, true); return;
      case RouteKind::kApiUndrain: handle_api_drain(con, false); return;
      case RouteKind::kApiHost:
        if (admin_allowed(con)) respond_json(con, 200, host_json());
        return;
      case RouteKind::kApiCluster:
        if (admin_allowed(con)) respond_json(con, 200, cluster_json());
        return;
      case RouteKind::kBadMethod:
        metrics_.count_rejection(Rejection::kBadRequest);
        respond_page(con, 405, error_page(405, "Method not allowed", "This address does not take that method."),
                     {{"Allow", route.allowed}});
        return;
      case RouteKind::kNotFound:
        break;
    }
    refuse(con, 404, Rejection::kBadRequest, "Not found", "There is nothing at this address.");
  }

  void handle_start(const ConnectionPtr& con, const Route& route) {
    // Read while the browser is surely there: after a claim round it may have left. The whole address is
    // hashed into the index; its abuse key (an IPv6 address's /64) counts in the limits.
    const std::string participant = intake_.participant_address_of(con);
    const std::string address = PublicIntake<Server>::abuse_key(participant);
    const auto decision = start_limiter_.take(address, std::chrono::steady_clock::now());
    if (!decision.allowed) {
      metrics_.count_rejection(Rejection::kRateLimited);
      respond_page(con, 429, busy_page(static_cast<int>(decision.retry_after.count())),
                   {{"Retry-After", std::to_string(decision.retry_after.count())}});
      return;
    }
    std::string error;
    const auto params = parse_query(route.query, error);
    if (!params) {
      refuse(con, 400, Rejection::kBadRequest, "This link is not valid", error);
      return;
    }
    // The signature before anything else, so that unsigned links learn nothing about valid parameters.
    if (!config_.link_secret.empty() && !link_signature_valid(*params, config_.link_secret)) {
      refuse(con, 403, Rejection::kBadSignature, "This link is not valid",
             "The link's signature is missing or wrong. Please use the exact link your survey gave you.");
      return;
    }
    const StartParse parsed = parse_start_request(*params, scenario_names(config_.scenarios), config_.scenario_facts);
    if (!parsed.request) {
      refuse(con, 400, Rejection::kBadRequest, "This link is not valid", parsed.error);
      return;
    }
    if (const std::string problem = ros_request_problem(config_, *parsed.request); !problem.empty()) {
      refuse(con, 400, Rejection::kBadRequest, "This link is not valid", problem);
      return;
    }
    // A link published in the open can be given an end: exp, a Unix time, signed with the rest.
    if (config_.require_link_expiry && !parsed.request->expires_at) {
      refuse(con, 403, Rejection::kBadSignature, "This link is not valid",
             "The link has no expiry time. Please use the exact link your survey gave you.");
      return;
    }
    if (parsed.request->expires_at && *parsed.request->expires_at < static_cast<std::uint64_t>(unix_seconds_now())) {
      refuse(con, 410, Rejection::kBadSignature, "This link has expired",
             "The study link is no longer valid. Please go back to the survey or contact the researcher.");
      return;
    }
    // Several hosts: a uid this host has no session of starts only where the uid registry decides its home.
    const Claim claim = registry_ != nullptr ? needs_claim(parsed.request->uid) : Claim::kNo;
    if (claim == Claim::kUnknown) {
      // Whether the uid has a session here is unknown: starting one unclaimed could make a second home.
      metrics_.count_rejection(Rejection::kBusy);
      respond_page(con, 503, retry_later_page(kUndecidedRetrySeconds),
                   {{"Retry-After", std::to_string(kUndecidedRetrySeconds)}});
      return;
    }
    if (claim == Claim::kYes) {
      con->defer_http_response();
      ++claims_in_flight_;
      registry_->claim(parsed.request->uid, [this, con, request = *parsed.request, address, participant,
                                             query = route.query](const std::optional<std::string>& home) {
        --claims_in_flight_;
        if (home && *home == config_.host_id) {
          start_session(con, request, address, participant, true);
          return;
        }
        if (home) {
          send_to_home(con, *home, query);
        } else {
          // Too few hosts answered: nothing was decided, so the retry (here or elsewhere) is safe.
          metrics_.count_rejection(Rejection::kBusy);
          respond_page(con, 503, retry_later_page(kUndecidedRetrySeconds),
                       {{"Retry-After", std::to_string(kUndecidedRetrySeconds)}});
        }
        websocketpp::lib::error_code ec;
        con->send_http_response(ec);  // a browser that left meanwhile costs nothing
      });
      return;
    }
    if (claim == Claim::kLearn) {
      con->defer_http_response();
      registry_->learn(parsed.request->uid, [this, con, request = *parsed.request, address, participant,
                                             query = route.query](const LearnResult& result) {
        if (const auto home = learned_redirect(result, config_.host_id)) {
          // The uid lives on another host (the balancer's pool may land on a full host that is not its home):
          // the participant goes there, as after a claim that another host won.
          send_to_home(con, *home, query);
        } else if (result.kind == LearnKind::kDecided && result.home == config_.host_id) {
          // Its home is this host: the supervisor admits it if a slot is really free (the host may only have
          // looked full for the claims in flight), joins its session if one started meanwhile, else says busy.
          start_session(con, request, address, participant, true);
          return;
        } else {
          // No home yet, or nothing learned: busy, as before. This round proposed nothing of its own, so trying
          // another host is safe.
          metrics_.count_rejection(Rejection::kBusy);
          respond_page(con, 503, busy_page(kBusyRetrySeconds), {{"Retry-After", std::to_string(kBusyRetrySeconds)}});
        }
        websocketpp::lib::error_code ec;
        con->send_http_response(ec);  // a browser that left meanwhile costs nothing
      });
      return;
    }
    start_session(con, *parsed.request, address, participant, false);
  }

  // Whether /start of `uid` must ask the uid registry first.
  enum class Claim {
    kNo,       // this host has a session of the uid, or is shutting down
    kYes,      // a uid new here, and a free slot: the registry decides where it starts
    kLearn,    // a uid new here, but full or draining: the registry only tells whether it lives elsewhere
    kUnknown,  // the index could not be read: the participant retries in a moment
  };
  // A full or draining host claims nothing (its busy page sends the participant elsewhere, and nothing was
  // recorded); it only learns whether the uid already has a home on another host, to send it there.
  Claim needs_claim(const std::string& uid) {
    try {
      if (supervisor_.has_session_for_uid(uid)) return Claim::kNo;
    } catch (const std::exception& error) {
      std::fprintf(stderr, "[manager] /start of uid %s: cannot read the index (%s); asked to retry\n", uid.c_str(),
                   error.what());
      return Claim::kUnknown;
    }
    if (supervisor_.shutting_down()) return Claim::kNo;
    // Claims still deciding hold a slot each: two new uids must not both win this host's last slot, or the
    // loser would be homed here for good while other hosts have room.
    const bool full = static_cast<int>(supervisor_.table().size()) + claims_in_flight_ >= config_.max_sessions;
    return full || supervisor_.draining() ? Claim::kLearn : Claim::kYes;
  }
  int claims_in_flight_ = 0;  // claim rounds started by /start here and not yet decided (I/O thread only)

  // Admits `request` on this host, from `participant` (whole) counted as `address` (its abuse key);
  // `deferred`: the response was deferred already (after a claim round).
  void start_session(const ConnectionPtr& con, const StartRequest& request, const std::string& address,
                     const std::string& participant, bool deferred) {
    // A new session's answer waits for its index row, which is written off this thread: defer the response.
    struct Answer {
      bool given = false;
      bool deferred = false;
    };
    const auto answer = std::make_shared<Answer>();  // the reply may come after this function returned
    answer->deferred = deferred;
    supervisor_.start(request, address, participant, [this, con, answer](const StartOutcome& outcome) {
      answer->given = true;
      answer_start(con, outcome);
      if (answer->deferred) {
        websocketpp::lib::error_code ec;
        con->send_http_response(ec);  // a browser that left meanwhile costs nothing
      }
    });
    if (!answer->given && !answer->deferred) {
      answer->deferred = true;
      con->defer_http_response();
    }
  }

  // 303 to the uid's home host's /start with the same query: the balancer routes /<host>/ to that host, which
  // serves the uid from now on.
  void send_to_home(const ConnectionPtr& con, const std::string& home, const std::string& query) {
    const std::string location = "/" + home + "/start?" + query;
    respond_page(con, 303, "<!DOCTYPE html><title>Moved</title><a href=\"" + html_escape(location) + "\">Continue</a>\n",
                 {{"Location", location}});
  }

  void answer_start(const ConnectionPtr& con, const StartOutcome& outcome) {
    switch (outcome.kind) {
      case StartOutcome::Kind::kJoined:
      case StartOutcome::Kind::kStarted: {
        // Behind a balancer the session's path carries this host's prefix, which routes it back here.
        const std::string location = config_.public_url + config_.path_prefix + "/s/" + outcome.token + "/";
        respond_page(con, 302, "<!DOCTYPE html><title>Starting</title><a href=\"" + location + "\">Continue</a>\n",
                     {{"Location", location}});
        return;
      }
      case StartOutcome::Kind::kBusy:
        metrics_.count_rejection(Rejection::kBusy);
        respond_page(con, 503, busy_page(kBusyRetrySeconds), {{"Retry-After", std::to_string(kBusyRetrySeconds)}});
        return;
      case StartOutcome::Kind::kPreviousEnding:
        // Not the busy page and not a 503: a balancer or a participant must not take this as "try another
        // host", where a second session of the uid would start. The page reloads itself here.
        metrics_.count_rejection(Rejection::kBusy);
        respond_page(con, 409, previous_closing_page(kPreviousEndingRetrySeconds),
                     {{"Retry-After", std::to_string(kPreviousEndingRetrySeconds)}});
        return;
      case StartOutcome::Kind::kCompleted:
        metrics_.count_rejection(Rejection::kCompleted);
        respond_page(con, 409, completed_page());
        return;
      case StartOutcome::Kind::kTooManyUnspent: {
        // Sessions nobody opened yet end at the idle timeout, or are spent once their participant shows up.
        metrics_.count_rejection(Rejection::kUnspentLimit);
        const auto retry = std::max<long long>(1, std::min<long long>(config_.idle_timeout.count(), 60));
        respond_page(con, 429, busy_page(static_cast<int>(retry)), {{"Retry-After", std::to_string(retry)}});
        return;
      }
      case StartOutcome::Kind::kFailed:
        respond_page(con, 503, error_page(503, "The simulation could not start",
                                          "Something went wrong on our side. Please try the link again in a "
                                          "minute, or tell the researcher."));
        return;
    }
  }

  // A file of a session's page (`headers`: who may frame it), while the session is live.
  void handle_session_file(const ConnectionPtr& con, const Route& route, const Headers& headers) {
    const auto session = supervisor_.find(route.token);
    if (!session) {
      refuse(con, 404, Rejection::kUnknownSession, "Session not found",
             "This session link is not valid. Please use the link your survey gave you.");
      return;
    }
    if (!is_live(session->state) || session->state == SessionState::kEnding) {
      metrics_.count_rejection(Rejection::kEndedSession);
      respond_page(con, 410, session_ended_page(state_name(coming_state(*session))));
      return;
    }
    const auto path = detail::resolve_static_path(web_root_, "/" + route.file);
    bool ok = false;
    const std::string body = path ? read_file(*path, ok) : "";
    if (!ok) {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "There is nothing at this address.");
      return;
    }
    respond(con, 200, body, std::string(detail::mime_type_for(*path)), headers);
  }

  void handle_session_status(const ConnectionPtr& con, const Route& route,
                             const std::vector<std::string>& survey_origins) {
    const auto session = supervisor_.find(route.token);
    if (!session) {
      metrics_.count_rejection(Rejection::kUnknownSession);
      respond_json(con, 404, "{\"error\":\"unknown session\"}");
      return;
    }
    respond_json(con, 200, status_json(*session, std::chrono::system_clock::now(), survey_origins,
                                       session_kind_name(config_.session_kind)));
  }

  bool admin_allowed(const ConnectionPtr& con) {
    if (config_.admin_token.empty()) {
      refuse(con, 404, Rejection::kUnauthorized, "Not found", "Administration is not enabled on this server.");
      return false;
    }
    if (!admin_authorized(con->get_request_header("Authorization"), config_.admin_token)) {
      metrics_.count_rejection(Rejection::kUnauthorized);
      respond_page(con, 401, error_page(401, "Administrator token needed", "Log in with the admin token as password."),
                   {{"WWW-Authenticate", "Basic realm=\"rfbsim admin\", charset=\"UTF-8\""}});
      return false;
    }
    return true;
  }

  void handle_admin_page(const ConnectionPtr& con, const Route& route) {
    if (!admin_allowed(con)) return;
    // The page's addresses are relative to /admin (so that they work under any path prefix): /admin/ would
    // resolve them one folder too deep, so it is sent to /admin.
    if (route.file.empty() && split_target(con->get_resource()).first.back() == '/') {
      respond_page(con, 301, "<!DOCTYPE html><title>Admin</title><a href=\"../admin\">Admin</a>\n",
                   {{"Location", "../admin"}});
      return;
    }
    // Only the admin page's own files: /admin is admin.html, /admin/admin.js its script.
    const std::string file = route.file.empty() ? "admin.html" : route.file;
    if (file != "admin.html" && file != "admin.js") {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "There is nothing at this address.");
      return;
    }
    const std::filesystem::path path = std::filesystem::path(web_root_) / file;
    bool ok = false;
    const std::string body = read_file(path, ok);
    if (!ok) {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "The admin page is not installed.");
      return;
    }
    Headers headers = page_headers({});  // the admin page is never framed by a survey
    respond(con, 200, body, std::string(detail::mime_type_for(path)), headers);
  }

  void handle_api_sessions(const ConnectionPtr& con) {
    if (!admin_allowed(con)) return;
    std::string json = "{\"capacity\":" + std::to_string(config_.max_sessions) +
                       ",\"draining\":" + (supervisor_.draining() ? "true" : "false") + ",\"live\":[";
    bool first = true;
    for (Session* session : supervisor_.table().all()) {
      json += (first ? "" : ",") + session_json(*session, true);
      first = false;
    }
    json += "],\"recent\":[";
    first = true;
    try {
      for (const Session& session : supervisor_.recent(kAdminRecentSessions)) {
        if (is_live(session.state)) continue;
        json += (first ? "" : ",") + session_json(session, false);
        first = false;
      }
    } catch (const std::exception& error) {
      respond_json(con, 500, "{\"error\":\"" + json_escape(error.what()) + "\"}");
      return;
    }
    respond_json(con, 200, json + "]}");
  }

  // POST /api/drain and /api/undrain: the operator takes this host out of the balancer's pool for new uids
  // (the agent says drain, /healthz 503) while its live sessions go on, or puts it back.
  void handle_api_drain(const ConnectionPtr& con, bool drain) {
    if (!admin_allowed(con)) return;
    if (con->get_request_header("X-Rfbsim-Admin").empty()) {  // as for ending a session: no cross-site posts
      metrics_.count_rejection(Rejection::kUnauthorized);
      respond_json(con, 403, "{\"error\":\"send the X-Rfbsim-Admin header\"}");
      return;
    }
    if (supervisor_.draining() != drain) {
      std::fprintf(stderr, "[manager] %s by the administrator (%zu live session(s))\n",
                   drain ? "draining: no new participants" : "taking new participants again",
                   supervisor_.table().size());
    }
    supervisor_.set_draining(drain);
    respond_json(con, 200, host_json());
  }

  // This host for the admin page and the balancer's operator: its id, drain state and load.
  std::string host_json() {
    return "{\"host\":\"" + json_escape(config_.host_id) + "\",\"prefix\":\"" + json_escape(config_.path_prefix) +
           "\",\"draining\":" + (supervisor_.draining() ? "true" : "false") +
           ",\"shutting_down\":" + (supervisor_.shutting_down() ? "true" : "false") +
           ",\"live\":" + std::to_string(supervisor_.table().size()) +
           ",\"max\":" + std::to_string(config_.max_sessions) + "}";
  }

  // The cluster's hosts and where each one's pages live on the balancer's origin: the admin page's cluster
  // view asks each for its sessions there. A single host lists itself.
  std::string cluster_json() {
    std::string json = "{\"self\":\"" + json_escape(config_.host_id) + "\",\"prefix\":\"" +
                       json_escape(config_.path_prefix) + "\",\"hosts\":[";
    if (config_.cluster_peers.empty()) {
      json += "{\"id\":\"" + json_escape(config_.host_id) + "\",\"prefix\":\"" + json_escape(config_.path_prefix) +
              "\"}";
    }
    bool first = true;
    for (const ClusterPeer& peer : config_.cluster_peers) {
      // The balancer routes /<id>/ to host <id>; this host's own prefix may have been set otherwise.
      const std::string prefix = peer.id == config_.host_id && !config_.path_prefix.empty() ? config_.path_prefix
                                                                                            : "/" + peer.id;
      json += std::string(first ? "" : ",") + "{\"id\":\"" + json_escape(peer.id) + "\",\"prefix\":\"" +
              json_escape(prefix) + "\"}";
      first = false;
    }
    return json + "]}";
  }

  void handle_api_end(const ConnectionPtr& con, const Route& route) {
    if (!admin_allowed(con)) return;
    // A custom header cannot be sent cross-site without a CORS preflight (which we never grant): a page
    // elsewhere cannot make a logged-in browser end sessions.
    if (con->get_request_header("X-Rfbsim-Admin").empty()) {
      metrics_.count_rejection(Rejection::kUnauthorized);
      respond_json(con, 403, "{\"error\":\"send the X-Rfbsim-Admin header\"}");
      return;
    }
    if (!supervisor_.end_by_admin(route.session_id)) {
      respond_json(con, 404, "{\"error\":\"no live session " + std::to_string(route.session_id) + "\"}");
      return;
    }
    respond_json(con, 200, "{\"ending\":" + std::to_string(route.session_id) + "}");
  }

  // ------------------------------------------------------------------------------------------------------
  // WebSocket
  // ------------------------------------------------------------------------------------------------------
  bool reject_websocket(const ConnectionPtr& con, int status, Rejection reason, const std::string& message) {
    metrics_.count_rejection(reason);
    con->set_status(static_cast<websocketpp::http::status_code::value>(status));
    con->set_body(message + "\n");
    con->replace_header("Content-Type", "text/plain; charset=utf-8");
    return false;
  }

  bool validate_websocket(const ConnectionPtr& con) {
    const auto decision = upgrade_limiter_.take(intake_.client_address_of(con), std::chrono::steady_clock::now());
    if (!decision.allowed) {
      con->replace_header("Retry-After", std::to_string(decision.retry_after.count()));
      return reject_websocket(con, 429, Rejection::kRateLimited, "too many connection attempts; try again later");
    }
    const std::string& target = con->get_resource();
    if (target.size() > kMaxTarget) return reject_websocket(con, 414, Rejection::kBadRequest, "address too long");
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

  void open_websocket(connection_hdl hdl) {
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
      close_with(*con, ended ? coming_state(*ended) : SessionState::kCrashed);
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
                                                      : proxy_line_for(*con, intake_.forwarded_participant_of(con)));
    }
    if (session->state == SessionState::kRunning) relay->connect(session->port, session->unix_socket);
  }

  void forget_websocket(connection_hdl hdl) {
    pending_.erase(hdl);
    const auto it = relays_.find(hdl);
    if (it == relays_.end()) return;
    const auto relay = it->second;
    relays_.erase(it);
    relay->browser_gone();
    if (relay->kind() == RelayKind::kParticipant) supervisor_.client_disconnected(relay->session_id());
  }

  void take_over_from_earlier(const Session& session) {
    auto relays = relays_;  // closing calls back into forget_websocket
    for (auto& [hdl, relay] : relays) {
      if (relay->session_id() != session.id || relay->kind() != RelayKind::kParticipant) continue;
      metrics_.count_takeover();
      std::fprintf(stderr, "[manager] session %lld (uid %s): a newer browser took over; the earlier one is told\n",
                   static_cast<long long>(session.id), session.uid.c_str());
      relay->close(static_cast<websocketpp::close::status::value>(kTakenOverCode), kTakenOverReason);
    }
  }

  // Live sessions' streams as sim_rfb last reported them, for the per-session gauges.
  std::vector<SessionStream> session_streams() {
    std::vector<SessionStream> streams;
    for (Session* session : supervisor_.table().all()) {
      if (session->stream) streams.push_back({session->id, *session->stream});
    }
    return streams;
  }

  RelayCounts relay_counts() const {
    RelayCounts counts;
    for (const auto& [hdl, relay] : relays_) ++(relay->kind() == RelayKind::kWatch ? counts.watch : counts.participant);
    return counts;
  }

  // The session's socket closed under a relay. Usually the process is ending or gone, and its exit will
  // say why; give that a moment to arrive, then tell the browser what happened.
  void upstream_lost(RelayT& relay) {
    auto timer = std::make_shared<asio::steady_timer>(io_, kUpstreamLostGrace);
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

  asio::io_context& io_;
  const ManagerConfig& config_;
  Supervisor& supervisor_;
  Metrics& metrics_;
  std::string web_root_;
  bool tls_;
  RegistryClient* registry_;  // null without cluster_peers: a single host decides alone
  Server server_;
  std::map<connection_hdl, std::shared_ptr<RelayT>, std::owner_less<connection_hdl>> relays_;
  // A WebSocket handshake that passed validation and has not opened yet: its session and kind.
  struct Pending {
    std::string token;
    RelayKind kind = RelayKind::kParticipant;
  };
  std::map<connection_hdl, Pending, std::owner_less<connection_hdl>> pending_;
  RateLimiter start_limiter_;
  RateLimiter upgrade_limiter_;
  PublicIntake<Server> intake_;  // after server_, which it accepts for
  asio::steady_timer ping_timer_;
  bool listening_ = false;
};

// TLS settings for the public port: TLS 1.2 and later, the certificate chain and key loaded once, now,
// so that a bad file stops the manager at start-up rather than at the first participant.
std::shared_ptr<asio::ssl::context> make_tls_context(const ManagerConfig& config) {
  auto context = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
  context->set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                       asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                       asio::ssl::context::no_tlsv1_1 | asio::ssl::context::single_dh_use);
  boost::system::error_code ec;
  context->use_certificate_chain_file(config.tls_certificate, ec);
  if (ec) throw std::runtime_error("cannot load the TLS certificate " + config.tls_certificate + ": " + ec.message());
  context->use_private_key_file(config.tls_private_key, asio::ssl::context::pem, ec);
  if (ec) throw std::runtime_error("cannot load the TLS private key " + config.tls_private_key + ": " + ec.message());
  if (SSL_CTX_check_private_key(context->native_handle()) != 1) {
    throw std::runtime_error("the TLS private key " + config.tls_private_key + " does not match the certificate");
  }
  return context;
}

}  // namespace

std::unique_ptr<Frontend> make_frontend(asio::io_context& io, const ManagerConfig& config, Supervisor& supervisor,
                                        Metrics& metrics, const std::string& web_root,
                                        RegistryClient* registry) {
  if (config.tls_certificate.empty()) {
    auto frontend = std::make_unique<FrontendImpl<websocketpp::config::asio>>(io, config, supervisor, metrics,
                                                                              web_root, false, registry);
    frontend->listen();
    return frontend;
  }
  auto context = make_tls_context(config);
  auto frontend = std::make_unique<FrontendImpl<websocketpp::config::asio_tls>>(io, config, supervisor, metrics,
                                                                                web_root, true, registry);
  frontend->server().set_tls_init_handler([context](connection_hdl) { return context; });
  frontend->listen();
  return frontend;
}

}  // namespace rfbsim::manager
