// SPDX-License-Identifier: GPL-2.0-or-later
// WsTestClient: a real WebSocket client (websocketpp on asio, no TLS) for tests, with a blocking,
// byte-stream view of the binary messages it receives (RFB over WebSocket does not keep message
// boundaries, so tests read exact byte counts as from a socket).
//
// This header names no websocketpp type: websocketpp 0.8.2 only compiles as C++17, so its translation
// unit lives in a C++17 library while the tests that use it stay C++20.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rfbsim::test {

class WsTestClient {
 public:
  /// Opens ws://127.0.0.1:`port``path`, sending `origin` as the Origin header and offering
  /// `subprotocol` (empty = offer none). Throws std::runtime_error naming the cause when the
  /// handshake fails or takes longer than `timeout`.
  WsTestClient(int port, const std::string& path, const std::string& origin, const std::string& subprotocol,
               std::chrono::milliseconds timeout = std::chrono::seconds(5));
  /// Closes the connection if it is still open and joins the I/O thread.
  ~WsTestClient();
  WsTestClient(const WsTestClient&) = delete;
  WsTestClient& operator=(const WsTestClient&) = delete;

  /// Sends one binary message; false when the connection is not open.
  bool send_binary(const std::vector<std::uint8_t>& bytes);
  /// Takes exactly `count` bytes from the received binary messages, waiting up to `timeout`.
  /// Returns false (leaving what arrived queued) on timeout or when the connection closed first.
  bool read_exact(std::size_t count, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  /// The subprotocol the server accepted, from its Sec-WebSocket-Protocol header ("" when none).
  [[nodiscard]] std::string subprotocol() const;
  /// Binary messages received so far.
  [[nodiscard]] std::uint64_t binary_messages() const;
  /// Text messages received so far (a binary RFB stream should have none).
  [[nodiscard]] std::uint64_t text_messages() const;
  /// Whether the connection is open (false once either side closed it).
  [[nodiscard]] bool open() const;
  /// The status code of the close frame the server sent (1005 or 1006 when the connection ended without
  /// one), or -1 while the connection has not closed.
  [[nodiscard]] int remote_close_code() const;
  /// Starts a normal close (1001 going away) and waits up to `timeout` for it to finish.
  void close(std::chrono::milliseconds timeout = std::chrono::seconds(2));

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::test
