// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeServer over websocketpp's asio server on one I/O thread. Each connection's replies and publishes
// wait in the hub (bounded, oldest dropped); the I/O thread hands websocketpp only as much as keeps its own
// send buffer under kSocketBudget, so a client that stops reading costs the hub's bound plus this, never more.
// What a client makes the server refuse or drop is logged through rfbsim::log::limited, by kind, since anyone
// who reaches the port can cause it as often as they like; no line names the client's address.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "ros/bridge/rosbridge_server.hpp"

#include <condition_variable>
#include <cstdint>
#include <iterator>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "rfbsim/log.hpp"
#include "ros/bridge/rosbridge_session.hpp"

namespace rfbsim::ros {

namespace asio = boost::asio;

namespace {

// Bytes handed to websocketpp per connection and not yet written to the socket, at most (one larger frame
// may go alone). Enough to keep a fast client busy; small next to the hub's bound.
constexpr std::size_t kSocketBudget = std::size_t{256} << 10;
// How soon a backlogged connection is looked at again, and how often held-back throttled messages are.
constexpr auto kRetryDelay = std::chrono::milliseconds(5);
constexpr auto kThrottleTick = std::chrono::milliseconds(25);
// A message this far over the limit is refused by websocketpp itself (close 1009, no status first), so that
// a peer cannot make us buffer more than this.
constexpr std::size_t kHardLimitFactor = 4;
// Sockets accepted and not yet gone, at most, as a multiple of max_connections: a socket that never finishes
// its handshake holds a descriptor until websocketpp's open-handshake timeout (5 s), and max_connections
// only counts completed handshakes, so without this a local user could run sim_rfb out of descriptors.
constexpr std::size_t kSocketsPerConnection = 4;
// How long shutdown waits for queued frames and close handshakes to go out.
constexpr auto kShutdownGrace = std::chrono::seconds(1);

}  // namespace

struct RosbridgeServer::Impl {
  using Endpoint = websocketpp::server<websocketpp::config::asio>;
  using Handle = websocketpp::connection_hdl;
  using MessagePtr = Endpoint::message_ptr;

  struct Peer {
    int hub_id = 0;
    std::unique_ptr<RosbridgeSession> session;
    std::unique_ptr<asio::steady_timer> retry;
    bool retry_armed = false;
    bool closing = false;
    bool told_dropping = false;  // the log has heard that this connection loses messages
  };

  Impl(RosbridgeHub& hub_in, RosbridgeServerOptions options_in) : hub(hub_in), options(std::move(options_in)) {
    if (options.port < 0 || options.port > 65535) throw std::invalid_argument("RosbridgeServer: bad port");
    if (options.max_connections < 1) throw std::invalid_argument("RosbridgeServer: max_connections < 1");
    if (options.max_message_bytes == 0) throw std::invalid_argument("RosbridgeServer: max_message_bytes is 0");
    boost::system::error_code address_ec;
    const asio::ip::address address = asio::ip::make_address(options.bind, address_ec);
    if (address_ec) throw std::invalid_argument("RosbridgeServer: bad bind address '" + options.bind + "'");

    endpoint.clear_access_channels(websocketpp::log::alevel::all);
    endpoint.clear_error_channels(websocketpp::log::elevel::all);
    endpoint.init_asio();
    endpoint.set_reuse_addr(true);
    endpoint.set_max_message_size(options.max_message_bytes * kHardLimitFactor + 4096);
    throttle_timer = std::make_unique<asio::steady_timer>(endpoint.get_io_service());

    // Handlers run on the I/O thread.
    endpoint.set_validate_handler([this](Handle hdl) { return validate(hdl); });
    endpoint.set_http_handler([this](Handle hdl) { plain_http(hdl); });
    endpoint.set_open_handler([this](Handle hdl) { open(hdl); });
    endpoint.set_close_handler([this](Handle hdl) { forget(hdl); });
    endpoint.set_fail_handler([this](Handle hdl) { forget(hdl); });
    endpoint.set_tcp_pre_init_handler([this](Handle hdl) { admit_socket(hdl); });
    endpoint.set_message_handler([this](Handle hdl, MessagePtr message) { receive(hdl, message); });

    // Listen before the thread starts, so that port() is known at once.
    websocketpp::lib::error_code ec;
    endpoint.listen(asio::ip::tcp::endpoint(address, static_cast<unsigned short>(options.port)), ec);
    if (!ec) endpoint.start_accept(ec);
    if (ec) {
      throw std::runtime_error("RosbridgeServer: cannot listen on " + options.bind + ":" +
                               std::to_string(options.port) + ": " + ec.message());
    }
    boost::system::error_code port_ec;
    port = endpoint.get_local_endpoint(port_ec).port();
    if (port_ec) throw std::runtime_error("RosbridgeServer: no local port: " + port_ec.message());
    arm_throttle_tick();
    io = std::thread([this] { endpoint.run(); });
  }

  ~Impl() {
    // Hand every client what the hub still holds for it (the session's last events, say), then say goodbye
    // (1001): websocketpp sends in order, the close frame last. Give both a moment, then stop.
    asio::post(endpoint.get_io_service(), [this] {
      websocketpp::lib::error_code ec;
      endpoint.stop_listening(ec);
      throttle_timer->cancel();
      for (auto& [hdl, peer] : peers) {
        if (peer.retry) peer.retry->cancel();
        const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl, ec);
        if (!ec && connection->get_state() == websocketpp::session::state::open) {
          for (const Frame& frame : hub.take_outgoing(peer.hub_id, SIZE_MAX)) {
            if (connection->send(*frame, websocketpp::frame::opcode::text)) break;
          }
        }
        endpoint.close(hdl, websocketpp::close::status::going_away, "server shutting down", ec);
      }
    });
    {
      std::unique_lock lock(stats_mutex);
      stopped.wait_for(lock, kShutdownGrace, [this] { return stats.open == 0; });
    }
    endpoint.stop();
    if (io.joinable()) io.join();
    for (const auto& [hdl, peer] : peers) hub.close_connection(peer.hub_id);
  }

  // Every accepted socket passes here before its handshake is read; beyond the cap it is closed at once
  // (websocketpp then fails the connection on its first read).
  void admit_socket(Handle hdl) {
    // A handle expires when websocketpp frees its connection, however it ended (plain HTTP included).
    for (auto it = sockets.begin(); it != sockets.end();) it = it->expired() ? sockets.erase(it) : std::next(it);
    if (sockets.size() >= kSocketsPerConnection * static_cast<std::size_t>(options.max_connections)) {
      websocketpp::lib::error_code ec;
      const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl, ec);
      boost::system::error_code close_ec;
      if (!ec) connection->get_raw_socket().close(close_ec);
      count([](RosbridgeServerStats& s) { ++s.sockets_refused; });
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "rosbridge-sockets-refused", "ros",
                           "rosbridge: closed a socket at accept: %zu sockets open already (4 x the %d connections)",
                           sockets.size(), options.max_connections);
      return;
    }
    sockets.insert(hdl);
  }

  bool validate(Handle hdl) {
    const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl);
    const std::string resource = connection->get_resource();
    if (resource.substr(0, resource.find('?')) != "/") {
      connection->set_status(websocketpp::http::status_code::not_found);
      count([](RosbridgeServerStats& s) { ++s.refused; });
      return false;
    }
    if (admitted.size() >= static_cast<std::size_t>(options.max_connections)) {
      connection->set_status(websocketpp::http::status_code::service_unavailable);
      count([](RosbridgeServerStats& s) { ++s.refused; });
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "rosbridge-connection-limit", "ros",
                           "rosbridge: refused a connection (503): at the limit of %d connections",
                           options.max_connections);
      return false;
    }
    admitted.insert(hdl);
    return true;
  }

  void plain_http(Handle hdl) {
    const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl);
    const std::string resource = connection->get_resource();
    if (resource.substr(0, resource.find('?')) == "/") {
      connection->set_status(websocketpp::http::status_code::upgrade_required);
      connection->set_body("rosbridge v2: open a WebSocket here\n");
    } else {
      connection->set_status(websocketpp::http::status_code::not_found);
      connection->set_body("not found\n");
    }
  }

  void open(Handle hdl) {
    Peer peer;
    HubConnectionOptions hub_options;
    hub_options.max_queued_bytes = options.max_queued_bytes_per_connection;
    // Runs with the hub's lock held, on any thread: only post.
    hub_options.wakeup = [this, hdl] { asio::post(endpoint.get_io_service(), [this, hdl] { flush(hdl); }); };
    peer.hub_id = hub.open_connection(std::move(hub_options));
    peer.session = std::make_unique<RosbridgeSession>(hub, peer.hub_id);
    peer.retry = std::make_unique<asio::steady_timer>(endpoint.get_io_service());
    peers.emplace(hdl, std::move(peer));
    count([](RosbridgeServerStats& s) {
      ++s.open;
      ++s.opened;
    });
  }

  void forget(Handle hdl) {
    admitted.erase(hdl);
    const auto found = peers.find(hdl);
    if (found == peers.end()) return;
    // websocketpp's own refusal of a message far over the limit (receive() never saw it): 1009, no status.
    websocketpp::lib::error_code ec;
    const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl, ec);
    if (!ec && !found->second.closing &&
        connection->get_local_close_code() == websocketpp::close::status::message_too_big) {
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "rosbridge-oversized", "ros",
                           "rosbridge: closed a connection (1009): a message over %zu bytes, read no further",
                           options.max_message_bytes * kHardLimitFactor + 4096);
    }
    found->second.retry->cancel();
    hub.close_connection(found->second.hub_id);
    peers.erase(found);
    count([](RosbridgeServerStats& s) { --s.open; });
    stopped.notify_all();
  }

  void receive(Handle hdl, const MessagePtr& message) {
    const auto found = peers.find(hdl);
    if (found == peers.end() || found->second.closing) return;
    Peer& peer = found->second;
    const std::string& payload = message->get_payload();
    if (payload.size() > options.max_message_bytes) {
      // The status goes straight to websocketpp, past any backlog in the hub (which is dropped with the
      // connection): websocketpp sends in order and the close frame last.
      websocketpp::lib::error_code ec;
      const std::optional<std::string> status =
          peer.session->oversized_status(payload.size(), options.max_message_bytes);
      if (status) endpoint.send(hdl, *status, websocketpp::frame::opcode::text, ec);
      peer.closing = true;
      endpoint.close(hdl, websocketpp::close::status::message_too_big, "message too big", ec);
      count([](RosbridgeServerStats& s) { ++s.closed_oversized; });
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "rosbridge-oversized", "ros",
                           "rosbridge: closed a connection (1009): a message of %zu bytes, over the limit of %zu",
                           payload.size(), options.max_message_bytes);
      return;
    }
    if (message->get_opcode() == websocketpp::frame::opcode::text) {
      peer.session->on_text(payload);
    } else {
      peer.session->on_binary();
    }
  }

  // Hands the connection's queued frames to websocketpp while its send buffer has room.
  void flush(Handle hdl) {
    const auto found = peers.find(hdl);
    if (found == peers.end()) return;
    Peer& peer = found->second;
    websocketpp::lib::error_code ec;
    const Endpoint::connection_ptr connection = endpoint.get_con_from_hdl(hdl, ec);
    if (ec || connection->get_state() != websocketpp::session::state::open) return;
    while (connection->get_buffered_amount() < kSocketBudget) {
      const std::deque<Frame> frames = hub.take_outgoing(peer.hub_id, kSocketBudget - connection->get_buffered_amount());
      if (frames.empty()) break;
      for (const Frame& frame : frames) {
        ec = connection->send(*frame, websocketpp::frame::opcode::text);
        if (ec) return;
      }
    }
    // Once per connection: the log hears that a slow reader loses its oldest messages (the hub's bound).
    if (!peer.told_dropping && hub.dropped(peer.hub_id) > 0) {
      peer.told_dropping = true;
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "rosbridge-slow-reader", "ros",
                           "rosbridge: a connection reads too slowly; its oldest messages are dropped beyond %zu "
                           "queued bytes",
                           options.max_queued_bytes_per_connection);
    }
    // Still backlogged: websocketpp has no "drained" callback, so look again shortly.
    if (hub.has_outgoing(peer.hub_id) && !peer.retry_armed) {
      peer.retry_armed = true;
      peer.retry->expires_after(kRetryDelay);
      peer.retry->async_wait([this, hdl](const boost::system::error_code& wait_ec) {
        if (wait_ec) return;
        const auto again = peers.find(hdl);
        if (again == peers.end()) return;
        again->second.retry_armed = false;
        flush(hdl);
      });
    }
  }

  // Releases throttled messages when the simulation publishes nothing for a while.
  void arm_throttle_tick() {
    throttle_timer->expires_after(kThrottleTick);
    throttle_timer->async_wait([this](const boost::system::error_code& ec) {
      if (ec) return;
      if (!peers.empty()) hub.flush_due();
      arm_throttle_tick();
    });
  }

  template <typename Edit>
  void count(Edit edit) {
    const std::lock_guard lock(stats_mutex);
    edit(stats);
  }

  RosbridgeHub& hub;
  const RosbridgeServerOptions options;
  Endpoint endpoint;
  int port = 0;
  std::unique_ptr<asio::steady_timer> throttle_timer;
  std::map<Handle, Peer, std::owner_less<Handle>> peers;       // I/O thread only
  std::set<Handle, std::owner_less<Handle>> admitted;           // I/O thread only: handshakes let through
  std::set<Handle, std::owner_less<Handle>> sockets;            // I/O thread only: accepted, maybe gone
  mutable std::mutex stats_mutex;
  std::condition_variable stopped;
  RosbridgeServerStats stats;  // guarded by stats_mutex
  std::thread io;
};

RosbridgeServer::RosbridgeServer(RosbridgeHub& hub, RosbridgeServerOptions options)
    : impl_(std::make_unique<Impl>(hub, std::move(options))) {}

RosbridgeServer::~RosbridgeServer() = default;

int RosbridgeServer::port() const { return impl_->port; }

RosbridgeServerStats RosbridgeServer::stats() const {
  const std::lock_guard lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace rfbsim::ros
