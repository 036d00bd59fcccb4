// SPDX-License-Identifier: GPL-2.0-or-later
// RawSocket: a blocking-with-deadline loopback TCP client for tests that must send bytes no real
// client would (garbage, truncated handshakes, lying length fields) and watch how the server reacts.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::test {

class RawSocket {
 public:
  /// Connects to 127.0.0.1:`port`. A `receive_buffer` > 0 shrinks SO_RCVBUF before connecting, so that
  /// a peer whose bytes are not read fills it quickly. Throws std::runtime_error when the connection fails.
  explicit RawSocket(int port, int receive_buffer = 0);
  /// Closes the socket if still open (an orderly close).
  ~RawSocket();
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;

  /// Sends every byte, waiting up to `timeout` for buffer space; false on error or timeout.
  bool send_all(std::string_view bytes, std::chrono::milliseconds timeout = std::chrono::seconds(5));
  bool send_all(const std::vector<std::uint8_t>& bytes, std::chrono::milliseconds timeout = std::chrono::seconds(5));
  /// Receives exactly `count` bytes into `out`; false on timeout, EOF or error (out then holds what came).
  bool read_exact(std::size_t count, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  /// Receives until the peer closes (or resets) the connection or `timeout` passes; returns the bytes.
  /// `closed` tells which of the two ended the wait.
  std::string read_until_closed(std::chrono::milliseconds timeout, bool* closed = nullptr);
  /// Receives until `terminator` has arrived (returns everything up to and including it) or `timeout`
  /// passes or the peer closes (returns ""). Reads byte by byte so nothing after the terminator is taken.
  std::string read_until(std::string_view terminator, std::chrono::milliseconds timeout);
  /// Aborts the connection: SO_LINGER 0 then close, so the peer sees a reset (RST) instead of a FIN.
  void reset();
  /// An orderly close (FIN).
  void close();
  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

}  // namespace rfbsim::test
