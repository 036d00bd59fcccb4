// SPDX-License-Identifier: GPL-2.0-or-later
// WsEchoServer: a loopback WebSocket server (ws or wss, websocketpp) that echoes binary messages and
// closes on demand with a chosen code, to test WebSocket clients such as WsRfbBridge.
//
// This header names no websocketpp or Boost type (see ws_rfb_bridge.hpp for why).
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>

namespace rfbsim::test {

/// How WsEchoServer answers; every field has a working default.
struct WsEchoServerOptions {
  /// PEM certificate and key (e.g. from make_test_certificate) to serve wss; both "" serves plain ws.
  std::string cert_pem;
  std::string key_pem;
  /// Nonzero: refuse every opening handshake with this HTTP status (e.g. 403) instead of 101.
  int reject_status = 0;
};

class WsEchoServer {
 public:
  /// Listens on 127.0.0.1 at an ephemeral port, accepting any path, and starts its one I/O thread.
  /// Accepts the "binary" subprotocol when offered. Throws std::runtime_error when it cannot listen or
  /// load the certificate.
  explicit WsEchoServer(WsEchoServerOptions options = {});
  /// Stops listening, drops every connection (no close handshake) and joins the I/O thread.
  ~WsEchoServer();
  WsEchoServer(const WsEchoServer&) = delete;
  WsEchoServer& operator=(const WsEchoServer&) = delete;

  [[nodiscard]] int port() const;

  // Everything below may be called from any thread.

  /// Connections whose opening handshake succeeded, ever.
  [[nodiscard]] std::size_t opened() const;
  /// Connections open now.
  [[nodiscard]] std::size_t open_now() const;
  /// The Origin header of the most recent handshake request ("" when none came).
  [[nodiscard]] std::string last_origin() const;
  /// The resource (path and query) of the most recent handshake request.
  [[nodiscard]] std::string last_resource() const;
  /// Waits until opened() >= count; false on timeout.
  bool wait_opened(std::size_t count, std::chrono::milliseconds timeout) const;
  /// Starts a close handshake with `code` and `reason` on every open connection (asynchronous: returns
  /// before the frames are sent).
  void close_all(int code, const std::string& reason);
  /// Waits until no connection is open; false on timeout.
  bool wait_all_closed(std::chrono::milliseconds timeout) const;

  struct Impl;  // public only so that the implementation's templates can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::test
