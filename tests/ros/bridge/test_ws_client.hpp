// SPDX-License-Identifier: GPL-2.0-or-later
// TestWsClient: a blocking WebSocket client over a plain POSIX socket for the rosbridge server's tests. It
// writes the frames itself (RFC 6455), so a test controls exactly what goes out (oversized, binary,
// malformed) and when it reads (a client that never reads).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rfbsim::test {

/// One frame as the server sent it.
struct WsFrame {
  int opcode = 0;       ///< 1 text, 2 binary, 8 close, 9 ping, 10 pong
  std::string payload;  ///< for a close frame: 2 bytes of code, then the reason
};

class TestWsClient {
 public:
  /// Connects to 127.0.0.1:`port` and opens a WebSocket at `path`. `receive_buffer` > 0 shrinks the
  /// socket's receive buffer first (a slow client). Throws std::runtime_error when the handshake fails.
  explicit TestWsClient(int port, const std::string& path = "/", int receive_buffer = 0);
  ~TestWsClient();
  TestWsClient(const TestWsClient&) = delete;
  TestWsClient& operator=(const TestWsClient&) = delete;

  /// The HTTP status a GET at `path` gets: 101 when a WebSocket opens, 404, 503, ... (0: no answer).
  static int handshake_status(int port, const std::string& path, bool upgrade = true);

  /// Sends one masked frame (opcode 1 text, 2 binary).
  void send(std::string_view payload, int opcode = 1);
  /// Sends `value` as a text frame.
  void send_json(const nlohmann::json& value) { send(value.dump()); }
  /// The next frame, or nullopt after `timeout` or when the connection ended.
  std::optional<WsFrame> read_frame(std::chrono::milliseconds timeout);
  /// Reads text frames until one parses to JSON for which `match` is true; nullopt on timeout or close.
  std::optional<nlohmann::json> wait_for(const std::function<bool(const nlohmann::json&)>& match,
                                         std::chrono::milliseconds timeout = std::chrono::seconds(10));
  /// The code of the close frame the server sent (-1: none seen yet).
  [[nodiscard]] int close_code() const { return close_code_; }

 private:
  bool fill(std::chrono::steady_clock::time_point deadline);

  int fd_ = -1;
  std::string buffer_;  // bytes read and not yet framed
  int close_code_ = -1;
  bool ended_ = false;
};

}  // namespace rfbsim::test
