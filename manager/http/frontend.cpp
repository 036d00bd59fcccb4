// SPDX-License-Identifier: GPL-2.0-or-later
// The public port on websocketpp: the server's set-up, HTTP routing to each handler, and WebSockets handed to
// the gate (http/websocket_gate.hpp). The rules live elsewhere, apart from sockets: who may start a session
// (admission/), what /start answers (http/start_answers), the admin API's JSON (admin/).
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "http/frontend.hpp"

#include <cstdio>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/server.hpp>

#include "admin/admin_api.hpp"
#include "admission/home_claim.hpp"
#include "admission/start_admission.hpp"
#include "admission/unix_time.hpp"
#include "cluster/registry_client.hpp"
#include "http/page_files.hpp"
#include "http/pages.hpp"
#include "http/public_intake.hpp"
#include "http/routes.hpp"
#include "http/server_tuning.hpp"
#include "http/start_answers.hpp"
#include "http/tls_context.hpp"
#include "http/web_policy.hpp"
#include "http/websocket_gate.hpp"
#include "rfbsim/log.hpp"
#include "sessions/session_views.hpp"
#include "static_files.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using websocketpp::connection_hdl;

// How many ended sessions the admin API lists besides the live ones.
constexpr int kAdminRecentSessions = 200;

template <typename WsConfig>
class FrontendImpl final : public Frontend, public SessionListener {
 public:
  using Server = websocketpp::server<WsConfig>;
  using ConnectionPtr = typename Server::connection_ptr;

  FrontendImpl(asio::io_context& io, const ManagerConfig& config, Supervisor& supervisor, Metrics& metrics,
               std::string web_root, bool tls, RegistryClient* registry)
      : io_(io),
        config_(config),
        supervisor_(supervisor),
        metrics_(metrics),
        web_root_(std::move(web_root)),
        tls_(tls),
        registry_(registry),
        admission_(config),
        intake_(io, server_, config, metrics),
        gate_(io, config, supervisor, metrics, server_, intake_) {
    tune_server(server_, io_, WebSocketGate<Server>::kMaxMessageSize);
    // No exception leaves a handler: a request that trips one costs its own connection, never the I/O loop
    // that carries every session.
    server_.set_http_handler([this](connection_hdl hdl) {
      guarded("an HTTP request", hdl, [&] { handle_http(server_.get_con_from_hdl(hdl)); });
    });
    server_.set_validate_handler([this](connection_hdl hdl) {
      bool accepted = false;
      guarded("a WebSocket handshake", hdl, [&] { accepted = gate_.validate(server_.get_con_from_hdl(hdl)); });
      return accepted;
    });
    server_.set_open_handler([this](connection_hdl hdl) { guarded("a WebSocket", hdl, [&] { gate_.open(hdl); }); });
    server_.set_close_handler([this](connection_hdl hdl) { gate_.forget(hdl); });
    server_.set_fail_handler([this](connection_hdl hdl) { gate_.forget(hdl); });
    server_.set_message_handler([this](connection_hdl hdl, typename Server::message_ptr message) {
      gate_.from_browser(hdl, std::move(message->get_raw_payload()));
    });
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
    intake_.start();
    gate_.start();
  }

  int port() const override {
    boost::system::error_code ec;
    const auto endpoint = const_cast<Server&>(server_).get_local_endpoint(ec);
    return ec ? 0 : endpoint.port();
  }
  const char* scheme() const override { return tls_ ? "https" : "http"; }

  void stop() override {
    websocketpp::lib::error_code ec;
    intake_.stop();
    server_.stop_listening(ec);
    gate_.stop();
  }

  // Runs `work` for connection `hdl`; an exception is logged and ends that connection only.
  template <typename Work>
  void guarded(const char* what, connection_hdl hdl, Work&& work) {
    try {
      work();
    } catch (const std::exception& error) {
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "handler-exception", "manager",
                           "%s failed: %s; its connection is closed", what, error.what());
      websocketpp::lib::error_code ec;
      auto con = server_.get_con_from_hdl(hdl, ec);
      if (!ec) con->terminate(ec);
    }
  }

  // SessionListener
  void session_ready(const Session& session) override { gate_.session_ready(session); }
  void session_closing(const Session& session) override { gate_.session_closing(session); }

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
    if (target.size() > kMaxRequestTarget) {
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
                     health_json(draining, static_cast<int>(supervisor_.table().size()), config_.max_sessions));
        return;
      }
      case RouteKind::kMetrics:
        metrics_.set_connections(intake_.open_total(), intake_.addresses());
        respond(con, 200,
                metrics_.render(supervisor_.counts_by_state(), config_.max_sessions, gate_.relay_counts(),
                                live_streams(supervisor_.table().all())),
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
        if (admin_allowed(con)) respond_json(con, 200, admin_cluster_json(config_));
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
    StartDecision decision =
        admission_.decide(route.query, address, std::chrono::steady_clock::now(), unix_seconds_now());
    if (decision.kind != StartDecision::Kind::kAdmitted) {
      reply(con, answer_refused_start(decision));
      return;
    }
    const StartRequest& request = *decision.request;
    // Several hosts: a uid this host has no session of starts only where the uid registry decides its home.
    const Claim claim = registry_ != nullptr ? needs_claim(request.uid) : Claim::kNo;
    if (claim == Claim::kUnknown) {
      // Whether the uid has a session here is unknown: starting one unclaimed could make a second home.
      reply(con, answer_home_undecided());
      return;
    }
    if (claim == Claim::kYes) {
      con->defer_http_response();
      ++claims_in_flight_;
      registry_->claim(request.uid, [this, con, request, address, participant,
                                     query = route.query](const std::optional<std::string>& home) {
        --claims_in_flight_;
        if (home && *home == config_.host_id) {
          start_session(con, request, address, participant, true);
          return;
        }
        // Elsewhere, or too few hosts answered: nothing was decided, so the retry (here or elsewhere) is safe.
        reply(con, home ? answer_go_home(*home, query) : answer_home_undecided());
        websocketpp::lib::error_code ec;
        con->send_http_response(ec);  // a browser that left meanwhile costs nothing
      });
      return;
    }
    if (claim == Claim::kLearn) {
      con->defer_http_response();
      registry_->learn(request.uid, [this, con, request, address, participant,
                                     query = route.query](const LearnResult& result) {
        if (const auto home = learned_redirect(result, config_.host_id)) {
          // The uid lives on another host (the balancer's pool may land on a full host that is not its home):
          // the participant goes there, as after a claim that another host won.
          reply(con, answer_go_home(*home, query));
        } else if (result.kind == LearnKind::kDecided && result.home == config_.host_id) {
          // Its home is this host: the supervisor admits it if a slot is really free (the host may only have
          // looked full for the claims in flight), joins its session if one started meanwhile, else says busy.
          start_session(con, request, address, participant, true);
          return;
        } else {
          // No home yet, or nothing learned: busy, as before. This round proposed nothing of its own, so trying
          // another host is safe.
          reply(con, answer_busy());
        }
        websocketpp::lib::error_code ec;
        con->send_http_response(ec);  // a browser that left meanwhile costs nothing
      });
      return;
    }
    start_session(con, request, address, participant, false);
  }

  // Whether /start of `uid` must ask the uid registry first (admission/home_claim.hpp).
  Claim needs_claim(const std::string& uid) {
    ClaimInputs in;
    try {
      in.has_session = supervisor_.has_session_for_uid(uid);
    } catch (const std::exception& error) {
      rfbsim::log::warn("manager", "/start of uid %s: cannot read the index (%s); asked to retry", uid.c_str(),
                        error.what());
    }
    in.shutting_down = supervisor_.shutting_down();
    in.draining = supervisor_.draining();
    in.live_sessions = static_cast<int>(supervisor_.table().size());
    in.claims_in_flight = claims_in_flight_;
    in.max_sessions = config_.max_sessions;
    return home_claim(in);
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
      reply(con, answer_start_outcome(outcome, config_));
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

  // An answer to /start, counted as its rejection if it is one.
  void reply(const ConnectionPtr& con, const PageAnswer& page) {
    if (page.rejection) metrics_.count_rejection(*page.rejection);
    respond_page(con, page.status, page.html, page.headers);
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
    const auto body = path ? read_page_file(*path) : std::nullopt;
    if (!body) {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "There is nothing at this address.");
      return;
    }
    respond(con, 200, *body, std::string(detail::mime_type_for(*path)), headers);
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
    const auto file = admin_page_file(route.file);
    if (!file) {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "There is nothing at this address.");
      return;
    }
    const std::filesystem::path path = std::filesystem::path(web_root_) / *file;
    const auto body = read_page_file(path);
    if (!body) {
      refuse(con, 404, Rejection::kBadRequest, "Not found", "The admin page is not installed.");
      return;
    }
    // The admin page is never framed by a survey.
    respond(con, 200, *body, std::string(detail::mime_type_for(path)), page_headers({}));
  }

  void handle_api_sessions(const ConnectionPtr& con) {
    if (!admin_allowed(con)) return;
    try {
      respond_json(con, 200, admin_sessions_json(config_.max_sessions, supervisor_.draining(), supervisor_.table().all(),
                                                 supervisor_.recent(kAdminRecentSessions)));
    } catch (const std::exception& error) {
      respond_json(con, 500, admin_error_json(error.what()));
    }
  }

  // POST /api/drain and /api/undrain: the operator takes this host out of the balancer's pool for new uids
  // (the agent says drain, /healthz 503) while its live sessions go on, or puts it back.
  void handle_api_drain(const ConnectionPtr& con, bool drain) {
    if (!admin_post_allowed(con)) return;
    if (supervisor_.draining() != drain) {
      rfbsim::log::info("manager", "%s by the administrator (%zu live session(s))",
                        drain ? "draining: no new participants" : "taking new participants again",
                        supervisor_.table().size());
    }
    supervisor_.set_draining(drain);
    respond_json(con, 200, host_json());
  }

  std::string host_json() {
    return admin_host_json({config_.host_id, config_.path_prefix, supervisor_.draining(), supervisor_.shutting_down(),
                            static_cast<int>(supervisor_.table().size()), config_.max_sessions});
  }

  void handle_api_end(const ConnectionPtr& con, const Route& route) {
    if (!admin_post_allowed(con)) return;
    if (!supervisor_.end_by_admin(route.session_id)) {
      respond_json(con, 404, admin_error_json("no live session " + std::to_string(route.session_id)));
      return;
    }
    respond_json(con, 200, admin_ending_json(route.session_id));
  }

  // An admin POST: the token, and a custom header, which cannot be sent cross-site without a CORS preflight
  // (which we never grant), so that a page elsewhere cannot make a logged-in browser end or drain sessions.
  bool admin_post_allowed(const ConnectionPtr& con) {
    if (!admin_allowed(con)) return false;
    if (con->get_request_header("X-Rfbsim-Admin").empty()) {
      metrics_.count_rejection(Rejection::kUnauthorized);
      respond_json(con, 403, admin_error_json("send the X-Rfbsim-Admin header"));
      return false;
    }
    return true;
  }

  asio::io_context& io_;
  const ManagerConfig& config_;
  Supervisor& supervisor_;
  Metrics& metrics_;
  std::string web_root_;
  bool tls_;
  RegistryClient* registry_;  // null without cluster_peers: a single host decides alone
  Server server_;
  StartAdmission admission_;
  PublicIntake<Server> intake_;   // after server_, which it accepts for
  WebSocketGate<Server> gate_;    // after intake_, which it asks for addresses
};

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
