// SPDX-License-Identifier: GPL-2.0-or-later
// RfbTestClient: a real RFB client (libvncclient) for tests and benchmarks: connect over TCP, receive
// Tight/JPEG updates into an RGBA framebuffer, send keys and pointer.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rfbsim/frame.hpp"

struct _rfbClient;

namespace rfbsim::test {

class RfbTestClient {
 public:
  /// Connects and completes the RFB handshake, asking for Tight with JPEG at `quality` (0..9).
  /// Throws std::runtime_error when the connection or the handshake fails.
  RfbTestClient(const std::string& host, int port, int quality = 8);
  ~RfbTestClient();
  RfbTestClient(const RfbTestClient&) = delete;
  RfbTestClient& operator=(const RfbTestClient&) = delete;

  /// Handles server messages until `done()` holds, the connection fails, or `timeout` passes.
  /// Returns whether `done()` held.
  bool pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout);
  /// Waits until `count` more complete framebuffer updates have arrived.
  bool wait_for_updates(std::uint64_t count, std::chrono::milliseconds timeout);

  /// Complete framebuffer updates received so far.
  [[nodiscard]] std::uint64_t updates() const { return updates_; }
  /// Whether the connection still works (false after a read error or the server closing it).
  [[nodiscard]] bool connected() const { return connected_; }
  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;
  /// The client's picture as RGBA (alpha undefined), top row first.
  [[nodiscard]] FrameView frame() const;
  /// The desktop name the server announced.
  [[nodiscard]] std::string desktop_name() const;

  void send_key(std::uint32_t keysym, bool down);
  void send_pointer(int x, int y, int buttons);

 private:
  static void on_update_finished(_rfbClient* client);
  _rfbClient* client_ = nullptr;
  std::vector<std::uint8_t> pixels_;
  std::uint64_t updates_ = 0;
  bool connected_ = false;
};

/// Mean absolute difference per colour channel (0..255) between two RGB(A) frames of equal size.
double mean_abs_difference(const FrameView& a, const FrameView& b);

/// Sends an HTTP GET on loopback and returns the whole response (head and body); "" on failure.
std::string http_get(int port, const std::string& path, std::chrono::milliseconds timeout = std::chrono::seconds(5));

/// The body of an HTTP response, after the blank line.
std::string http_body(const std::string& response);

/// Reads a number field from a flat JSON text such as the status document: json_number(t, "x") finds
/// the first "x": value. Returns NaN when absent.
double json_number(const std::string& json, const std::string& key);

}  // namespace rfbsim::test
