// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeClient over websocketpp's asio client (plain or TLS) on one I/O thread, which also runs the
// reconnect timer. What goes out waits in the hub (bounded); the I/O thread keeps websocketpp's own send
// buffer under kSocketBudget, as the server does. Logs through a LogLimiter: once per change of state, so
// that a lab's server that is down for an hour costs one line, not one per retry, and never faster than one
// line a second per kind whatever the server sends.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "ros/bridge/rosbridge_client.hpp"

#include <algorithm>
#include <atomic>
#include <boost/asio/ssl/host_name_verification.hpp>
#include <condition_variable>
#include <cstdint>
#include <iostream>
#include <mutex>
#include <random>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "ros/bridge/log_limiter.hpp"
#include "ros/bridge/reconnect_backoff.hpp"
#include "ros/bridge/rosbridge_link.hpp"
#include "ros/bridge/ws_url.hpp"

namespace rfbsim::ros {

namespace asio = boost::asio;

namespace {

constexpr std::size_t kSocketBudget = std::size_t{256} << 10;
constexpr auto kRetryDelay = std::chrono::milliseconds(5);
constexpr auto kStableConnection = std::chrono::seconds(10);
// How long shutdown waits for queued frames and the close handshake to go out.
constexpr auto kShutdownGrace = std::chrono::seconds(1);

}  // namespace

struct RosbridgeClient::Impl {
  virtual ~Impl() = default;
  std::atomic<bool> connected{false};
  std::atomic<int> opened{0};
  std::atomic<int> failed{0};
};

namespace {

template <typename Config, bool kTls>
class Dialer final : public RosbridgeClient::Impl {
 public:
  using Endpoint = websocketpp::client<Config>;
  using Handle = websocketpp::connection_hdl;
  using MessagePtr = typename Endpoint::message_ptr;

  Dialer(RosbridgeHub& hub, RosbridgeClientOptions options, WsUrl url)
      : hub_(hub),
        options_(std::move(options)),
        url_(std::move(url)),
        link_(hub, [this](const std::string& line) { note("server", line); }),
        backoff_(options_.max_backoff),
        random_(std::random_device{}()) {
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio();
    endpoint_.start_perpetual();  // keep run() going between connections
    endpoint_.set_max_message_size(options_.max_message_bytes);
    if constexpr (kTls) {
      tls_context_ = make_tls_context();  // a bad ca_file throws here, from the constructor
      // SNI needs nothing here: websocketpp's TLS transport sets it from the URL's host on every client
      // connection (pre_init), IP addresses included, which RFC 6066 does not allow but servers ignore.
      endpoint_.set_tls_init_handler([this](Handle) { return tls_context_; });
    }
    if (!options_.token.empty() && !kTls) note("token", "warning: the token goes over plain ws:// to " + options_.url);

    // Handlers run on the I/O thread.
    endpoint_.set_open_handler([this](Handle hdl) { on_open(hdl); });
    endpoint_.set_fail_handler([this](Handle hdl) { on_fail(hdl); });
    endpoint_.set_close_handler([this](Handle hdl) { on_close(hdl); });
    endpoint_.set_message_handler([this](Handle, MessagePtr message) {
      last_heard_ = std::chrono::steady_clock::now();
      if (message->get_opcode() == websocketpp::frame::opcode::text) {
        link_.on_text(hub_id_, message->get_payload());
      } else {
        note("binary", "server sent a binary frame; rfbsim asks for JSON only");
      }
    });
    endpoint_.set_pong_handler([this](Handle, std::string) { last_heard_ = std::chrono::steady_clock::now(); });
    retry_timer_ = std::make_unique<asio::steady_timer>(endpoint_.get_io_service());
    flush_timer_ = std::make_unique<asio::steady_timer>(endpoint_.get_io_service());
    ping_timer_ = std::make_unique<asio::steady_timer>(endpoint_.get_io_service());
    asio::post(endpoint_.get_io_service(), [this] { dial(); });
    io_ = std::thread([this] { endpoint_.run(); });
  }

  ~Dialer() override {
    // Hand the server what the hub still holds (the session's last events, say), then close politely
    // (1001): websocketpp sends in order, the close frame last. Wait a moment for both, then stop.
    asio::post(endpoint_.get_io_service(), [this] {
      stopping_ = true;
      retry_timer_->cancel();
      flush_timer_->cancel();
      ping_timer_->cancel();
      if (!connected) return;
      websocketpp::lib::error_code ec;
      const typename Endpoint::connection_ptr connection = endpoint_.get_con_from_hdl(current_, ec);
      if (!ec && hub_id_ != 0 && connection->get_state() == websocketpp::session::state::open) {
        for (const Frame& frame : hub_.take_outgoing(hub_id_, SIZE_MAX)) {
          if (connection->send(*frame, websocketpp::frame::opcode::text)) break;
        }
      }
      endpoint_.close(current_, websocketpp::close::status::going_away, "rfbsim shutting down", ec);
    });
    {
      std::unique_lock lock(mutex_);
      closed_.wait_for(lock, kShutdownGrace, [this] { return !connected; });
    }
    endpoint_.stop_perpetual();
    endpoint_.stop();
    if (io_.joinable()) io_.join();
    if (hub_id_ != 0) hub_.close_connection(hub_id_);
  }

 private:
  using TlsContextPtr = websocketpp::lib::shared_ptr<asio::ssl::context>;

  TlsContextPtr make_tls_context() {
    auto context = websocketpp::lib::make_shared<asio::ssl::context>(asio::ssl::context::tls_client);
    context->set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                         asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                         asio::ssl::context::no_tlsv1_1);
    context->set_verify_mode(asio::ssl::verify_peer);
    boost::system::error_code ec;
    context->set_default_verify_paths(ec);
    if (!options_.ca_file.empty()) {
      context->load_verify_file(options_.ca_file, ec);
      if (ec) throw std::runtime_error("RosbridgeClient: cannot load ca_file " + options_.ca_file + ": " + ec.message());
    }
    // Chain and name: host_name_verification matches an IP-address host against the IP SANs.
    context->set_verify_callback(asio::ssl::host_name_verification(url_.host));
    return context;
  }

  void dial() {
    if (stopping_) return;
    websocketpp::lib::error_code ec;
    const typename Endpoint::connection_ptr connection = endpoint_.get_connection(options_.url, ec);
    if (ec) {
      ++failed;
      note("fail", "cannot connect to " + options_.url + ": " + ec.message());
      retry_later();
      return;
    }
    if (!options_.token.empty()) connection->append_header("Authorization", "Bearer " + options_.token);
    current_ = connection->get_handle();
    endpoint_.connect(connection);
  }

  void on_open(Handle hdl) {
    opened_at_ = std::chrono::steady_clock::now();
    HubConnectionOptions hub_options;
    hub_options.max_queued_bytes = options_.max_queued_bytes;
    hub_options.mirror_declared = true;
    hub_options.greeting = link_.greeting();
    // Runs with the hub's lock held, on any thread: only post.
    hub_options.wakeup = [this, hdl] { asio::post(endpoint_.get_io_service(), [this, hdl] { flush(hdl); }); };
    // The lab's server takes no status op: statuses the simulation sends this link are logged here instead.
    hub_options.local_status = [this](const std::string& text) { note("status", "status for the lab: " + text); };
    hub_id_ = hub_.open_connection(std::move(hub_options));
    ++opened;
    set_connected(true);
    note("connected", "connected to " + options_.url);
    last_heard_ = opened_at_;
    keep_alive(hdl);
  }

  // Pings every keepalive_interval and drops a link that has been silent for pong_timeout, so that the
  // reconnect starts instead of TCP's own give-up some 15 minutes later. websocketpp's own pong timer is no
  // use here: each ping restarts it, so with pings more often than the timeout it never fires.
  void keep_alive(Handle hdl) {
    ping_timer_->expires_after(options_.keepalive_interval);
    ping_timer_->async_wait([this, hdl](const boost::system::error_code& wait_ec) {
      if (wait_ec || stopping_) return;
      websocketpp::lib::error_code ec;
      const typename Endpoint::connection_ptr connection = endpoint_.get_con_from_hdl(hdl, ec);
      if (ec || connection->get_state() != websocketpp::session::state::open) return;
      if (std::chrono::steady_clock::now() - last_heard_ >= options_.pong_timeout) {
        silent_ = true;
        connection->terminate(std::make_error_code(std::errc::timed_out));  // no close handshake on a dead link
        return;
      }
      connection->ping("", ec);
      keep_alive(hdl);
    });
  }

  void on_fail(Handle hdl) {
    websocketpp::lib::error_code ec;
    const typename Endpoint::connection_ptr connection = endpoint_.get_con_from_hdl(hdl, ec);
    std::string reason = ec ? ec.message() : connection->get_ec().message();
    if (!ec && connection->get_response_code() != 0 &&
        connection->get_response_code() != websocketpp::http::status_code::switching_protocols) {
      reason = "HTTP " + std::to_string(static_cast<int>(connection->get_response_code())) + " " +
               connection->get_response_msg();
    }
    ++failed;
    note("fail", "cannot connect to " + options_.url + ": " + reason + "; retrying");
    retry_later();
  }

  void on_close(Handle hdl) {
    websocketpp::lib::error_code ec;
    const typename Endpoint::connection_ptr connection = endpoint_.get_con_from_hdl(hdl, ec);
    if (hub_id_ != 0) hub_.close_connection(hub_id_);
    hub_id_ = 0;
    ping_timer_->cancel();
    set_connected(false);
    std::string why = ec ? ec.message() : "code " + std::to_string(connection->get_remote_close_code());
    if (!ec && !connection->get_remote_close_reason().empty()) why += " " + connection->get_remote_close_reason();
    if (silent_) why = "no answer for " + std::to_string(options_.pong_timeout.count()) + " ms";
    silent_ = false;
    if (stopping_) return;  // our own goodbye
    // Back to quick retries only after a connection that lasted: a server that accepts and at once hangs up
    // (a refused token, say) is retried ever more slowly, like one that is down.
    if (std::chrono::steady_clock::now() - opened_at_ >= kStableConnection) backoff_.reset();
    note("lost", "connection to " + options_.url + " lost (" + why + "); reconnecting");
    retry_later();
  }

  void retry_later() {
    if (stopping_) return;
    retry_timer_->expires_after(backoff_.next(std::uniform_real_distribution<double>(0.0, 1.0)(random_)));
    retry_timer_->async_wait([this](const boost::system::error_code& ec) {
      if (!ec) dial();
    });
  }

  // Hands queued frames to websocketpp while its send buffer has room.
  void flush(Handle hdl) {
    websocketpp::lib::error_code ec;
    const typename Endpoint::connection_ptr connection = endpoint_.get_con_from_hdl(hdl, ec);
    if (ec || hub_id_ == 0 || connection->get_state() != websocketpp::session::state::open) return;
    while (connection->get_buffered_amount() < kSocketBudget) {
      const std::deque<Frame> frames = hub_.take_outgoing(hub_id_, kSocketBudget - connection->get_buffered_amount());
      if (frames.empty()) break;
      for (const Frame& frame : frames) {
        ec = connection->send(*frame, websocketpp::frame::opcode::text);
        if (ec) return;
      }
    }
    if (hub_.has_outgoing(hub_id_) && !flush_armed_) {
      flush_armed_ = true;
      flush_timer_->expires_after(kRetryDelay);
      flush_timer_->async_wait([this, hdl](const boost::system::error_code& wait_ec) {
        flush_armed_ = false;
        if (!wait_ec) flush(hdl);
      });
    }
  }

  void set_connected(bool value) {
    {
      const std::lock_guard lock(mutex_);
      connected = value;
    }
    closed_.notify_all();
  }

  // Any thread (the hub's statuses come from the simulation thread): the limiter is thread-safe.
  void note(const std::string& kind, const std::string& line) {
    if (const std::optional<std::string> admitted = log_.admit(kind, line)) {
      std::cerr << "[rosbridge] " << *admitted << std::endl;
    }
  }

  RosbridgeHub& hub_;
  const RosbridgeClientOptions options_;
  const WsUrl url_;
  LogLimiter log_;
  RosbridgeLink link_;
  Endpoint endpoint_;
  TlsContextPtr tls_context_;  // wss only
  std::unique_ptr<asio::steady_timer> retry_timer_;
  std::unique_ptr<asio::steady_timer> flush_timer_;
  std::unique_ptr<asio::steady_timer> ping_timer_;
  // I/O thread only, below (and the destructor after the join).
  Handle current_;
  int hub_id_ = 0;
  bool stopping_ = false;
  bool flush_armed_ = false;
  bool silent_ = false;  // the connection is being dropped for silence
  ReconnectBackoff backoff_;
  std::minstd_rand random_;  // the backoff's jitter
  std::chrono::steady_clock::time_point opened_at_;
  std::chrono::steady_clock::time_point last_heard_;  // a pong or a message, or the open
  std::mutex mutex_;
  std::condition_variable closed_;
  std::thread io_;
};

}  // namespace

RosbridgeClient::RosbridgeClient(RosbridgeHub& hub, RosbridgeClientOptions options) {
  WsUrl url = parse_ws_url(options.url);
  if (options.max_backoff.count() <= 0) throw std::invalid_argument("RosbridgeClient: max_backoff must be > 0");
  if (options.keepalive_interval.count() <= 0 || options.pong_timeout.count() <= 0) {
    throw std::invalid_argument("RosbridgeClient: keepalive_interval and pong_timeout must be > 0");
  }
  if (url.tls) {
    impl_ = std::make_unique<Dialer<websocketpp::config::asio_tls_client, true>>(hub, std::move(options), std::move(url));
  } else {
    if (!options.ca_file.empty()) throw std::invalid_argument("RosbridgeClient: ca_file is for wss:// URLs only");
    impl_ = std::make_unique<Dialer<websocketpp::config::asio_client, false>>(hub, std::move(options), std::move(url));
  }
}

RosbridgeClient::~RosbridgeClient() = default;

bool RosbridgeClient::connected() const { return impl_->connected; }

int RosbridgeClient::connections_opened() const { return impl_->opened; }

int RosbridgeClient::failed_attempts() const { return impl_->failed; }

}  // namespace rfbsim::ros
