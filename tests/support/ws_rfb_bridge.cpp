// SPDX-License-Identifier: GPL-2.0-or-later
// WsRfbBridge over websocketpp's asio client (plain or TLS) and a Boost.Asio acceptor, all on one I/O
// thread; the records that other threads read sit behind one mutex.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "ws_rfb_bridge.hpp"

#include <array>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <boost/asio/ssl/host_name_verification.hpp>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>
#include <websocketpp/uri.hpp>

namespace rfbsim::test {

// The part every endpoint flavour shares: the per-connection records, read from any thread.
struct WsRfbBridge::Impl {
  virtual ~Impl() = default;

  int port = 0;
  mutable std::mutex mutex;
  mutable std::condition_variable changed;
  std::vector<WsBridgeConnection> connections;  // guarded by mutex

  // Appends a fresh record and returns its index.
  std::size_t add_connection() {
    std::size_t index = 0;
    {
      std::lock_guard lock(mutex);
      connections.emplace_back();
      index = connections.size() - 1;
    }
    changed.notify_all();
    return index;
  }

  // Applies `edit` to record `index` under the lock, then wakes the waiters.
  template <typename Edit>
  void update(std::size_t index, Edit edit) {
    {
      std::lock_guard lock(mutex);
      edit(connections[index]);
    }
    changed.notify_all();
  }
};

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

constexpr std::size_t kReadChunk = 64 * 1024;  // bytes per TCP read, hence at most per WebSocket message
// How long the TCP reader backs off while the WebSocket's send queue is over its limit. websocketpp
// has no "send queue drained" callback, so the reader re-checks on this timer instead.
constexpr auto kBackoff = std::chrono::milliseconds(1);

// One bridged connection: the TCP client and its WebSocket. Touched only on the I/O thread. Owned by
// the handlers that are pending for it (TCP operations, the WebSocket connection's handlers); it holds
// the WebSocket only weakly, so no ownership cycle keeps either alive.
struct Session {
  Session(asio::io_service& io, std::size_t record) : index(record), socket(io), backoff(io) {}

  std::size_t index;  // into Impl::connections
  tcp::socket socket;
  asio::steady_timer backoff;
  websocketpp::connection_hdl ws;
  std::array<char, kReadChunk> read_buffer{};
  std::deque<std::string> to_client;  // WebSocket payloads waiting for the TCP write
  std::size_t to_client_bytes = 0;    // their total size
  bool writing = false;               // a TCP write is in flight
  bool ws_open = false;               // the WebSocket is open (not yet closing or closed)
  bool ws_done = false;               // the WebSocket ended: closed, or its handshake failed
  bool tcp_closed = false;            // the bridge closed the TCP socket
};
using SessionPtr = std::shared_ptr<Session>;

template <typename Config, bool kTls>
class Relay final : public WsRfbBridge::Impl {
 public:
  using Endpoint = websocketpp::client<Config>;
  using ConnectionPtr = typename Endpoint::connection_ptr;
  using MessagePtr = typename Endpoint::message_ptr;

  Relay(std::string url, WsRfbBridgeOptions options) : url_(std::move(url)), options_(std::move(options)) {
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio();
    if constexpr (kTls) {
      // One context for every connection, made here so that a bad ca_file throws from the constructor.
      tls_context_ = make_tls_context();
      endpoint_.set_tls_init_handler([this](websocketpp::connection_hdl) { return tls_context_; });
    }
    // RFB's small messages (a key, a pointer move) must not wait for Nagle's algorithm on either hop.
    endpoint_.set_tcp_post_init_handler([this](websocketpp::connection_hdl hdl) {
      websocketpp::lib::error_code ec;
      const ConnectionPtr connection = endpoint_.get_con_from_hdl(hdl, ec);
      boost::system::error_code ignored;
      if (!ec) connection->get_raw_socket().set_option(tcp::no_delay(true), ignored);
    });
    // The listening socket, before the thread starts, so that port() is known and run() has work.
    acceptor_ = std::make_unique<tcp::acceptor>(endpoint_.get_io_service());
    boost::system::error_code ec;
    const tcp::endpoint loopback(asio::ip::address_v4::loopback(), 0);
    acceptor_->open(loopback.protocol(), ec);
    if (!ec) acceptor_->bind(loopback, ec);
    if (!ec) acceptor_->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw std::runtime_error("WsRfbBridge: cannot listen on 127.0.0.1: " + ec.message());
    port = acceptor_->local_endpoint().port();
    accept_next();
    io_ = std::thread([this] { endpoint_.run(); });
  }

  // Stops the I/O thread first; pending handlers (and the sessions they own) go with the io_service,
  // which Asio documents as the way to release such objects.
  ~Relay() override {
    endpoint_.stop();
    if (io_.joinable()) io_.join();
    acceptor_.reset();  // before the endpoint, which owns the io_service it uses
  }

 private:
  using TlsContextPtr = websocketpp::lib::shared_ptr<asio::ssl::context>;

  TlsContextPtr make_tls_context() {
    auto context = websocketpp::lib::make_shared<asio::ssl::context>(asio::ssl::context::tls_client);
    if (!options_.verify_certificate) {
      context->set_verify_mode(asio::ssl::verify_none);
      return context;
    }
    context->set_verify_mode(asio::ssl::verify_peer);
    if (options_.ca_file.empty()) {
      context->set_default_verify_paths();
    } else {
      boost::system::error_code ec;
      context->load_verify_file(options_.ca_file, ec);
      if (ec) throw std::runtime_error("WsRfbBridge: cannot load CA file " + options_.ca_file + ": " + ec.message());
    }
    // Chain and name: host_name_verification matches an IP-address host against the IP SANs.
    context->set_verify_callback(asio::ssl::host_name_verification(websocketpp::uri(url_).get_host()));
    return context;
  }

  void accept_next() {
    auto session = std::make_shared<Session>(endpoint_.get_io_service(), 0);
    acceptor_->async_accept(session->socket, [this, session](const boost::system::error_code& ec) {
      if (ec == asio::error::operation_aborted) return;  // shutting down
      if (!ec) {
        boost::system::error_code ignored;
        session->socket.set_option(tcp::no_delay(true), ignored);
        session->index = add_connection();
        open_websocket(session);
      }
      accept_next();
    });
  }

  // Starts the WebSocket for a fresh TCP client. The TCP side is only read once the WebSocket is
  // open: RFB's server speaks first, so nothing is lost by waiting.
  void open_websocket(const SessionPtr& session) {
    websocketpp::lib::error_code ec;
    const ConnectionPtr connection = endpoint_.get_connection(url_, ec);
    if (ec) {
      update(session->index, [&](WsBridgeConnection& c) {
        c.handshake_failed = true;
        c.error = "bad URL " + url_ + ": " + ec.message();
      });
      session->ws_done = true;
      close_tcp(session);
      return;
    }
    if (!options_.origin.empty()) connection->replace_header("Origin", options_.origin);
    for (const auto& [name, value] : options_.extra_headers) connection->replace_header(name, value);
    if (!options_.subprotocol.empty()) connection->add_subprotocol(options_.subprotocol, ec);

    connection->set_open_handler([this, session](websocketpp::connection_hdl hdl) { on_open(session, hdl); });
    connection->set_fail_handler([this, session](websocketpp::connection_hdl hdl) { on_fail(session, hdl); });
    connection->set_close_handler([this, session](websocketpp::connection_hdl hdl) { on_close(session, hdl); });
    connection->set_message_handler(
        [this, session](websocketpp::connection_hdl, MessagePtr message) { on_message(session, message); });
    session->ws = connection->get_handle();
    endpoint_.connect(connection);
  }

  void on_open(const SessionPtr& session, websocketpp::connection_hdl hdl) {
    const ConnectionPtr connection = endpoint_.get_con_from_hdl(hdl);
    update(session->index, [&](WsBridgeConnection& c) {
      c.opened = true;
      c.handshake_status = static_cast<int>(connection->get_response_code());
      // websocketpp's client does not record the accepted subprotocol; read it from the response.
      c.subprotocol = connection->get_response_header("Sec-WebSocket-Protocol");
    });
    session->ws_open = true;
    read_tcp(session);
  }

  void on_fail(const SessionPtr& session, websocketpp::connection_hdl hdl) {
    const ConnectionPtr connection = endpoint_.get_con_from_hdl(hdl);
    update(session->index, [&](WsBridgeConnection& c) {
      c.handshake_failed = !c.opened;
      c.handshake_status = static_cast<int>(connection->get_response_code());
      c.error = connection->get_ec().message();
    });
    session->ws_open = false;
    session->ws_done = true;
    close_tcp(session);
  }

  // Marks the record finished once both sides are.
  void settle(const SessionPtr& session) {
    if (!session->tcp_closed || !session->ws_done) return;
    update(session->index, [](WsBridgeConnection& c) { c.finished = true; });
  }

  void on_close(const SessionPtr& session, websocketpp::connection_hdl hdl) {
    const ConnectionPtr connection = endpoint_.get_con_from_hdl(hdl);
    update(session->index, [&](WsBridgeConnection& c) {
      c.close_code = static_cast<int>(connection->get_remote_close_code());
      c.close_reason = connection->get_remote_close_reason();
    });
    session->ws_open = false;
    session->ws_done = true;
    // Whatever the server sent before its close frame still reaches the client (e.g. an RFB failure
    // reason): write_tcp closes the TCP socket once that is written.
    write_tcp(session);
    settle(session);
  }

  // Starts the bridge's own close of the WebSocket (the client left or fell behind).
  void close_websocket(const SessionPtr& session, websocketpp::close::status::value code, const std::string& reason) {
    if (!session->ws_open) return;
    session->ws_open = false;
    update(session->index, [](WsBridgeConnection& c) { c.closed_by_bridge = true; });
    websocketpp::lib::error_code ec;
    endpoint_.close(session->ws, code, reason, ec);
    // On error the connection is already going away and its close or fail handler still runs.
  }

  void close_tcp(const SessionPtr& session) {
    if (!session->tcp_closed) {
      session->tcp_closed = true;
      boost::system::error_code ignored;
      session->socket.shutdown(tcp::socket::shutdown_both, ignored);
      session->socket.close(ignored);
      session->backoff.cancel();
      // to_client stays: a cancelled write may still point into its front until its handler runs.
    }
    settle(session);
  }

  // TCP -> WebSocket: one binary message per read.
  void read_tcp(const SessionPtr& session) {
    if (session->tcp_closed || !session->ws_open) return;
    session->socket.async_read_some(
        asio::buffer(session->read_buffer), [this, session](const boost::system::error_code& ec, std::size_t n) {
          if (session->tcp_closed) return;
          if (ec) {
            // The client left (EOF) or its socket failed: end the WebSocket normally.
            close_websocket(session, websocketpp::close::status::normal, "client closed");
            close_tcp(session);
            return;
          }
          if (!session->ws_open) return;  // closing: drop what the client still sends
          websocketpp::lib::error_code send_ec;
          endpoint_.send(session->ws, session->read_buffer.data(), n, websocketpp::frame::opcode::binary, send_ec);
          if (send_ec) return;  // the WebSocket is ending; its close handler closes the TCP side
          update(session->index, [n](WsBridgeConnection& c) { c.bytes_to_server += n; });
          continue_reading(session);
        });
  }

  // Reads on at once, or backs off while the WebSocket still has too much queued to send.
  void continue_reading(const SessionPtr& session) {
    websocketpp::lib::error_code ec;
    const ConnectionPtr connection = endpoint_.get_con_from_hdl(session->ws, ec);
    if (ec) return;
    if (connection->get_buffered_amount() <= options_.max_ws_buffered_bytes) {
      read_tcp(session);
      return;
    }
    session->backoff.expires_after(kBackoff);
    session->backoff.async_wait([this, session](const boost::system::error_code& wait_ec) {
      if (!wait_ec) continue_reading(session);
    });
  }

  // WebSocket -> TCP: payloads queue in order and are written one at a time.
  void on_message(const SessionPtr& session, const MessagePtr& message) {
    if (session->tcp_closed) return;
    session->to_client.push_back(message->get_payload());
    session->to_client_bytes += message->get_payload().size();
    if (session->to_client_bytes > options_.max_tcp_queued_bytes) {
      // RFB is pull-based, so this much unread means the client is stuck; bound the memory instead.
      update(session->index, [](WsBridgeConnection& c) { c.error = "TCP client fell too far behind"; });
      close_websocket(session, websocketpp::close::status::going_away, "client too slow");
      close_tcp(session);
      return;
    }
    write_tcp(session);
  }

  void write_tcp(const SessionPtr& session) {
    if (session->writing || session->tcp_closed) return;
    if (session->to_client.empty()) {
      if (session->ws_done) close_tcp(session);  // all that arrived before the close is delivered
      return;
    }
    session->writing = true;
    asio::async_write(session->socket, asio::buffer(session->to_client.front()),
                      [this, session](const boost::system::error_code& ec, std::size_t n) {
                        session->writing = false;
                        if (session->tcp_closed) return;
                        if (ec) {
                          close_websocket(session, websocketpp::close::status::going_away, "client gone");
                          close_tcp(session);
                          return;
                        }
                        session->to_client_bytes -= session->to_client.front().size();
                        session->to_client.pop_front();
                        update(session->index, [n](WsBridgeConnection& c) { c.bytes_to_client += n; });
                        write_tcp(session);
                      });
  }

  const std::string url_;
  const WsRfbBridgeOptions options_;
  TlsContextPtr tls_context_;  // wss only; used on the I/O thread
  Endpoint endpoint_;                        // owns the io_service
  std::unique_ptr<tcp::acceptor> acceptor_;  // on endpoint_'s io_service
  std::thread io_;
};

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

}  // namespace

WsRfbBridge::WsRfbBridge(const std::string& url, WsRfbBridgeOptions options) {
  const websocketpp::uri parsed(url);
  if (!parsed.get_valid() || !(starts_with(url, "ws://") || starts_with(url, "wss://"))) {
    throw std::invalid_argument("WsRfbBridge: not a ws:// or wss:// URL: " + url);
  }
  if (parsed.get_secure()) {
    impl_ = std::make_unique<Relay<websocketpp::config::asio_tls_client, true>>(url, std::move(options));
  } else {
    impl_ = std::make_unique<Relay<websocketpp::config::asio_client, false>>(url, std::move(options));
  }
}

WsRfbBridge::WsRfbBridge(const std::string& url, const std::string& origin, WsRfbBridgeOptions options)
    : WsRfbBridge(url, [&] {
        options.origin = origin;
        return std::move(options);
      }()) {}

WsRfbBridge::~WsRfbBridge() = default;

int WsRfbBridge::port() const { return impl_->port; }

std::size_t WsRfbBridge::connection_count() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections.size();
}

WsBridgeConnection WsRfbBridge::connection(std::size_t index) const {
  std::lock_guard lock(impl_->mutex);
  return index < impl_->connections.size() ? impl_->connections[index] : WsBridgeConnection{};
}

WsBridgeConnection WsRfbBridge::last() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections.empty() ? WsBridgeConnection{} : impl_->connections.back();
}

bool WsRfbBridge::wait_for_connections(std::size_t count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->changed.wait_for(lock, timeout, [&] { return impl_->connections.size() >= count; });
}

bool WsRfbBridge::wait_last_finished(std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->changed.wait_for(
      lock, timeout, [&] { return !impl_->connections.empty() && impl_->connections.back().finished; });
}

}  // namespace rfbsim::test
