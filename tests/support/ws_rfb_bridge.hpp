// SPDX-License-Identifier: GPL-2.0-or-later
// WsRfbBridge: a loopback TCP port that relays each accepted connection to a WebSocket server (ws:// or
// wss://), so that a raw-TCP RFB client such as RfbTestClient can reach a WebSocket-only endpoint.
//
// This header names no websocketpp or Boost type: websocketpp 0.8.2 only compiles as C++17 with g++ 12,
// so the implementation lives in a C++17 library while the tests that use it stay C++20.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace rfbsim::test {

/// How the bridge opens its WebSocket connections; every field has a working default.
struct WsRfbBridgeOptions {
  /// Origin header to send; "" sends none.
  std::string origin;
  /// Subprotocol to offer; noVNC offers "binary". "" offers none.
  std::string subprotocol = "binary";
  /// Further request headers (name, value), e.g. a Cookie, sent on every handshake.
  std::vector<std::pair<std::string, std::string>> extra_headers;
  /// wss:// only: check the server's certificate chain and that it names the URL's host. Off by default
  /// because tests use self-signed certificates.
  bool verify_certificate = false;
  /// wss:// with verify_certificate only: a PEM file of trusted certificates (e.g. the self-signed
  /// cert.pem itself); "" uses the system's default trust store.
  std::string ca_file;
  /// TCP -> WebSocket: while the WebSocket has more than this many bytes queued unsent, the bridge
  /// stops reading that TCP connection (re-checking every millisecond).
  std::size_t max_ws_buffered_bytes = std::size_t{1} << 20;
  /// WebSocket -> TCP: when more than this many bytes wait for the TCP client to take them, the bridge
  /// gives up on it and closes both sides (RFB is pull-based, so a live client never gets near this).
  std::size_t max_tcp_queued_bytes = std::size_t{64} << 20;
};

/// What happened to one bridged connection. A snapshot: copy it out, it does not update.
struct WsBridgeConnection {
  /// The WebSocket opening handshake succeeded.
  bool opened = false;
  /// The WebSocket opening handshake (or the TCP/TLS connect before it) failed.
  bool handshake_failed = false;
  /// HTTP status of the server's answer to the opening handshake: 101 after a successful one, the
  /// refusal's status (403, 404, 503, ...) after a failed one, 0 when no HTTP answer came back.
  int handshake_status = 0;
  /// The subprotocol the server accepted ("" when none).
  std::string subprotocol;
  /// The status code in the close frame the server sent (as websocketpp reports it: 1005 when the
  /// frame had no code, 1006 when the connection ended without a close frame); -1 before the end or
  /// after a failed handshake.
  int close_code = -1;
  /// The reason text in the server's close frame ("" when none).
  std::string close_reason;
  /// The bridge started the close, because the TCP client left or fell too far behind; close_code is
  /// then the server's answer (1000 echoed, or 1006 from a server that just drops the connection).
  bool closed_by_bridge = false;
  /// websocketpp's error text for a failure ("" when none).
  std::string error;
  /// Payload bytes read from the TCP client and handed to the WebSocket for sending.
  std::uint64_t bytes_to_server = 0;
  /// Payload bytes written to the TCP client. Counted when the write completes on the I/O thread, so
  /// it may trail what the client has already read; final once `finished`.
  std::uint64_t bytes_to_client = 0;
  /// Both sides are finished: the WebSocket ended (or never opened) and the TCP socket is closed.
  bool finished = false;
};

class WsRfbBridge {
 public:
  /// Listens on 127.0.0.1 at an ephemeral port and starts the one I/O thread. `url` is
  /// ws://HOST:PORT/PATH or wss://HOST:PORT/PATH; each accepted TCP connection opens its own WebSocket
  /// connection to it; several may be open at once. Throws std::invalid_argument for a URL that is neither, std::runtime_error when
  /// the listening socket cannot be set up or options.ca_file cannot be loaded.
  explicit WsRfbBridge(const std::string& url, WsRfbBridgeOptions options = {});
  /// Convenience: `options` with `origin` set.
  WsRfbBridge(const std::string& url, const std::string& origin, WsRfbBridgeOptions options = {});
  /// Drops every connection at once (no close handshake), stops the I/O thread and joins it.
  ~WsRfbBridge();
  WsRfbBridge(const WsRfbBridge&) = delete;
  WsRfbBridge& operator=(const WsRfbBridge&) = delete;

  /// The loopback TCP port to point a raw RFB client at.
  [[nodiscard]] int port() const;

  // Everything below may be called from any thread.

  /// Connections accepted so far (in accept order, index 0 first).
  [[nodiscard]] std::size_t connection_count() const;
  /// A snapshot of connection `index` (< connection_count(); otherwise a default-constructed one).
  [[nodiscard]] WsBridgeConnection connection(std::size_t index) const;
  /// A snapshot of the most recently accepted connection (default-constructed before the first).
  [[nodiscard]] WsBridgeConnection last() const;
  /// Shorthands for last()'s fields.
  [[nodiscard]] int last_close_code() const { return last().close_code; }
  [[nodiscard]] std::string last_close_reason() const { return last().close_reason; }
  [[nodiscard]] int last_handshake_status() const { return last().handshake_status; }
  [[nodiscard]] bool last_handshake_failed() const { return last().handshake_failed; }

  /// Waits until at least `count` connections have been accepted; false on timeout.
  bool wait_for_connections(std::size_t count, std::chrono::milliseconds timeout) const;
  /// Waits until the most recent connection is finished (see WsBridgeConnection::finished); false on
  /// timeout or when no connection was accepted yet.
  bool wait_last_finished(std::chrono::milliseconds timeout) const;

  struct Impl;  // public only so that the implementation's templates can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::test
