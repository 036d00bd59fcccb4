// SPDX-License-Identifier: GPL-2.0-or-later
// LabServer: a stand-in for a lab's rosbridge_server in the dial-out client's tests: a loopback WebSocket
// server (ws or wss, websocketpp) that records each handshake's Authorization header and every text frame,
// and sends text frames on demand. No rosbridge logic: the tests read what the client sent.
//
// This header names no websocketpp or Boost type (C++17 implementation, C++20 tests).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace rfbsim::test {

/// How LabServer listens.
struct LabServerOptions {
  int port = 0;          ///< 0: any free port; a given one is bound with SO_REUSEADDR (restart tests)
  std::string cert_pem;  ///< both set: wss with this certificate and key
  std::string key_pem;
};

class LabServer {
 public:
  /// Listens on 127.0.0.1 and starts its I/O thread; throws std::runtime_error when it cannot.
  explicit LabServer(LabServerOptions options = {});
  /// Drops every connection at once (no close handshake, as a crashed server would) and joins the thread.
  ~LabServer();
  LabServer(const LabServer&) = delete;
  LabServer& operator=(const LabServer&) = delete;

  [[nodiscard]] int port() const;

  // Any thread:
  /// Connections whose handshake succeeded, ever.
  [[nodiscard]] std::size_t opened() const;
  /// The Authorization header of every handshake, in order ("" when absent).
  [[nodiscard]] std::vector<std::string> authorizations() const;
  /// Every text frame received, in order.
  [[nodiscard]] std::vector<std::string> received() const;
  /// Sends `text` as a text frame on every open connection (asynchronous).
  void send_all(const std::string& text);
  /// Pings received, ever.
  [[nodiscard]] std::size_t pings() const;
  /// Whether pings get a pong (true at first); false stands in for a link that died silently.
  void answer_pings(bool answer);

  struct Impl;  // public only so that the implementation's templates can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::test
