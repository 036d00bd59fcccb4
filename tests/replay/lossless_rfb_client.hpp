// SPDX-License-Identifier: GPL-2.0-or-later
// LosslessRfbClient: a real RFB client (libvncclient) that asks only for Raw, so that the pictures it holds
// are the server's pixels exactly: the replay frame test compares them with the video without the live
// stream's JPEG loss in the way.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

struct _rfbClient;

namespace rfbsim::test {

class LosslessRfbClient {
 public:
  /// Connects to `host`:`port` and completes the RFB handshake offering only the Raw encoding.
  /// Throws std::runtime_error when the connection or the handshake fails.
  LosslessRfbClient(const std::string& host, int port);
  ~LosslessRfbClient();
  LosslessRfbClient(const LosslessRfbClient&) = delete;
  LosslessRfbClient& operator=(const LosslessRfbClient&) = delete;

  /// Handles server messages for `duration` (updates keep coming: libvncclient asks again after each one).
  /// Returns false once the connection failed.
  bool pump(std::chrono::milliseconds duration);
  /// Asks for the whole picture (a non-incremental request) and waits up to `timeout` for it to arrive.
  /// Returns false on timeout or a failed connection.
  bool refresh(std::chrono::milliseconds timeout);

  /// The picture as RGB bytes (3 per pixel, top row first), as of the last update.
  [[nodiscard]] std::vector<std::uint8_t> rgb() const;
  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;

  void send_key(std::uint32_t keysym, bool down);

 private:
  static void on_update_finished(_rfbClient* client);
  bool handle_one(int wait_us);

  _rfbClient* client_ = nullptr;
  std::vector<std::uint8_t> pixels_;  // RGBX, owned here rather than by libvncclient
  std::uint64_t updates_ = 0;
  bool connected_ = false;
};

}  // namespace rfbsim::test
