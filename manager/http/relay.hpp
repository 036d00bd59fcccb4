// SPDX-License-Identifier: GPL-2.0-or-later
// Relay: one browser WebSocket carried to one session's loopback port as raw RFB, byte for byte; a watch
// relay (a researcher's view) passes the browser's bytes through an RfbInputFilter first, so that a watcher
// sees the session but cannot steer it.
//
// Flow control keeps the relay out of the session's picture of the link: the relay reads from the session
// only while the WebSocket's send buffer has room for a whole chunk within kMaxBuffered, so TCP pushes back at
// once and the session's own flow control gives that participant fewer, current frames. Input from the browser
// is small (keys); more than kMaxPending unsent bytes of it means a broken client, and it is closed.
//
// Templated on the websocketpp server type (plain or TLS); everything runs on the I/O thread.
#pragma once

#include <array>
#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <websocketpp/close.hpp>
#include <websocketpp/common/connection_hdl.hpp>
#include <websocketpp/frame.hpp>

#include "admin/metrics.hpp"
#include "http/rfb_input_filter.hpp"
#include "sessions/session_views.hpp"

namespace rfbsim::manager {

template <typename Server>
class Relay : public std::enable_shared_from_this<Relay<Server>> {
 public:
  /// At most this many bytes wait in the WebSocket's send buffer toward the browser. Small on purpose: sim_rfb's
  /// congestion control measures the whole path with fences (a fence comes back only after every byte before
  /// it reached the browser), and every byte queued here is queueing delay it sees as a longer round trip and
  /// then has to drain. A deep buffer (it was 1 MiB) hid the participant's link behind a second or more of
  /// backlog at a few Mbit/s; 64 KiB is about 50 ms at 10 Mbit/s, and still a few updates' worth on a fast link.
  static constexpr std::size_t kMaxBuffered = 64 * 1024;
  /// Bytes read from the session at once: a quarter of kMaxBuffered, so that one chunk never overshoots it.
  static constexpr std::size_t kReadChunk = kMaxBuffered / 4;
  static constexpr std::size_t kMaxPending = 1 << 20;
  static constexpr auto kDrainPoll = std::chrono::milliseconds(5);

  /// Bytes from the session that must have been relayed to the browser before a participant relay reports its
  /// first picture: more than the RFB handshake, the fence and the end-of-updates message (about 300 bytes from
  /// sim_rfb), less than any first full picture (14 KiB at 320x240, tens of KiB at the sizes studies use).
  static constexpr std::uint64_t kFirstPictureBytes = 1024;

  /// Called once when the session side closes or fails (not when close() was called first).
  using UpstreamLost = std::function<void(Relay&)>;
  /// Called once, for participant relays, when kFirstPictureBytes have been relayed to the browser.
  using PictureDelivered = std::function<void(Relay&)>;

  /// `kind` kWatch drops the browser's input (RfbInputFilter) and closes it on bytes that cannot be framed.
  Relay(Server& server, websocketpp::connection_hdl browser, std::int64_t session_id, std::string token,
        RelayKind kind, Metrics& metrics, UpstreamLost on_upstream_lost)
      : server_(server),
        browser_(std::move(browser)),
        session_id_(session_id),
        token_(std::move(token)),
        kind_(kind),
        metrics_(metrics),
        on_upstream_lost_(std::move(on_upstream_lost)),
        upstream_(server.get_io_service()),
        drain_timer_(server.get_io_service()) {}

  [[nodiscard]] std::int64_t session_id() const { return session_id_; }
  [[nodiscard]] const std::string& token() const { return token_; }
  [[nodiscard]] RelayKind kind() const { return kind_; }
  [[nodiscard]] bool connecting_or_connected() const { return connect_started_; }
  /// Whether close() or browser_gone() ran: the relay only waits for its browser's socket to finish closing.
  [[nodiscard]] bool closed() const { return closed_; }

  /// What to call when the first picture has gone to the browser (participant relays only).
  void on_picture_delivered(PictureDelivered callback) { on_picture_delivered_ = std::move(callback); }

  /// A PROXY protocol line naming the browser's address, sent to the session before any browser byte
  /// (sim_rfb records the participant's address, hashed, rather than ours). Call before connect().
  void set_proxy_line(std::string line) { proxy_line_ = std::move(line); }

  /// Connects to the session's loopback `port`, or to its `unix_socket` when that is not empty, and starts
  /// relaying (browser bytes received so far go first).
  void connect(int port, const std::string& unix_socket = "") {
    if (connect_started_ || closed_) return;
    connect_started_ = true;
    if (!proxy_line_.empty()) {
      pending_bytes_ += proxy_line_.size();
      pending_.push_front(proxy_line_);
    }
    const Endpoint endpoint =
        unix_socket.empty()
            ? Endpoint(boost::asio::ip::tcp::endpoint(boost::asio::ip::address_v4::loopback(),
                                                      static_cast<unsigned short>(port)))
            : Endpoint(boost::asio::local::stream_protocol::endpoint(unix_socket));
    upstream_.async_connect(endpoint, [self = this->shared_from_this()](const boost::system::error_code& ec) {
      if (self->closed_) return;
      if (ec) {
        self->lose_upstream();
        return;
      }
      boost::system::error_code ignored;  // no Nagle over TCP; a unix socket has none to switch off
      self->upstream_.set_option(boost::asio::ip::tcp::no_delay(true), ignored);
      self->connected_ = true;
      self->write_upstream();
      self->read_upstream();
    });
  }

  /// A binary message from the browser: raw RFB bytes for the session.
  void from_browser(std::string payload) {
    if (closed_) return;
    if (kind_ == RelayKind::kWatch) {
      payload = filter_.forward(payload);
      if (filter_.failed()) {
        close(websocketpp::close::status::policy_violation, filter_.failure());
        return;
      }
      if (payload.empty()) return;  // only input, all dropped
    }
    pending_bytes_ += payload.size();
    if (pending_bytes_ > kMaxPending) {
      close(websocketpp::close::status::message_too_big, "too much input");
      return;
    }
    pending_.push_back(std::move(payload));
    write_upstream();
  }

  /// Closes both sides: the browser with `code` and `reason` (if still open), the session's socket.
  void close(websocketpp::close::status::value code, const std::string& reason) {
    if (closed_) return;
    closed_ = true;
    boost::system::error_code ignored;
    drain_timer_.cancel();
    upstream_.close(ignored);
    websocketpp::lib::error_code ec;
    auto connection = server_.get_con_from_hdl(browser_, ec);
    if (!ec && connection->get_state() == websocketpp::session::state::open) connection->close(code, reason, ec);
  }

  /// Closes both sides with a session's close notice.
  void close(const CloseNotice& notice) {
    close(static_cast<websocketpp::close::status::value>(notice.code), notice.reason);
  }

  /// The browser's side is gone: drop the session's socket too.
  void browser_gone() {
    closed_ = true;
    boost::system::error_code ignored;
    drain_timer_.cancel();
    upstream_.close(ignored);
  }

 private:
  void lose_upstream() {
    if (closed_ || upstream_lost_) return;
    upstream_lost_ = true;
    if (on_upstream_lost_) on_upstream_lost_(*this);
  }

  void read_upstream() {
    upstream_.async_read_some(boost::asio::buffer(buffer_), [self = this->shared_from_this()](
                                                                const boost::system::error_code& ec,
                                                                std::size_t bytes) {
      if (self->closed_) return;
      if (ec) {
        self->lose_upstream();
        return;
      }
      websocketpp::lib::error_code send_ec;
      auto connection = self->server_.get_con_from_hdl(self->browser_, send_ec);
      if (send_ec) return;
      send_ec = connection->send(self->buffer_.data(), bytes, websocketpp::frame::opcode::binary);
      if (send_ec) return;  // the browser is going; its close handler cleans up
      self->metrics_.add_bytes_to_client(bytes);
      self->bytes_to_browser_ += bytes;
      self->report_picture_delivered();
      self->read_when_drained();
    });
  }

  // Reads the next chunk once it fits within kMaxBuffered beside what the browser has not taken yet.
  void read_when_drained() {
    websocketpp::lib::error_code ec;
    auto connection = server_.get_con_from_hdl(browser_, ec);
    if (ec || closed_) return;
    if (connection->get_buffered_amount() + kReadChunk <= kMaxBuffered) {
      read_upstream();
      return;
    }
    drain_timer_.expires_after(kDrainPoll);
    drain_timer_.async_wait([self = this->shared_from_this()](const boost::system::error_code& wait_ec) {
      if (!wait_ec) self->read_when_drained();
    });
  }

  // Relayed into the browser's WebSocket. At the start of a connection nothing else waits there (the flow
  // control above keeps it under kMaxBuffered in any case), so the picture is on its way to the browser's
  // socket at once; waiting for websocketpp to write it would race with an ending that closes the relay.
  void report_picture_delivered() {
    if (picture_reported_ || kind_ != RelayKind::kParticipant || !on_picture_delivered_) return;
    if (bytes_to_browser_ < kFirstPictureBytes) return;
    picture_reported_ = true;
    on_picture_delivered_(*this);
  }

  void write_upstream() {
    if (!connected_ || writing_ || pending_.empty() || closed_) return;
    writing_ = true;
    boost::asio::async_write(upstream_, boost::asio::buffer(pending_.front()),
                             [self = this->shared_from_this()](const boost::system::error_code& ec, std::size_t bytes) {
                               self->writing_ = false;
                               if (self->closed_) return;
                               if (ec) {
                                 self->lose_upstream();
                                 return;
                               }
                               self->metrics_.add_bytes_to_session(bytes);
                               self->pending_bytes_ -= self->pending_.front().size();
                               self->pending_.pop_front();
                               self->write_upstream();
                             });
  }

  Server& server_;
  websocketpp::connection_hdl browser_;
  std::int64_t session_id_;
  std::string token_;
  RelayKind kind_;
  RfbInputFilter filter_;  // used by watch relays only
  Metrics& metrics_;
  UpstreamLost on_upstream_lost_;
  PictureDelivered on_picture_delivered_;
  using Endpoint = boost::asio::generic::stream_protocol::endpoint;
  boost::asio::generic::stream_protocol::socket upstream_;  // TCP or unix, whichever the session serves on
  boost::asio::steady_timer drain_timer_;
  std::array<char, kReadChunk> buffer_{};
  std::deque<std::string> pending_;
  std::string proxy_line_;
  std::size_t pending_bytes_ = 0;
  std::uint64_t bytes_to_browser_ = 0;  // relayed from the session to the browser's WebSocket
  bool picture_reported_ = false;
  bool connect_started_ = false;
  bool connected_ = false;
  bool writing_ = false;
  bool closed_ = false;
  bool upstream_lost_ = false;
};

}  // namespace rfbsim::manager
