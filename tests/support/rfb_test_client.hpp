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

/// How the client asks for pictures.
enum class UpdateMode {
  kRequests,    ///< a plain client: one FramebufferUpdateRequest after each update (libvncclient's way)
  kContinuous,  ///< lists Fence and ContinuousUpdates, answers fences, enables ContinuousUpdates at the
                ///< server's first EndOfContinuousUpdates and from then on sends no update request
};

class RfbTestClient {
 public:
  /// Connects and completes the RFB handshake, asking for Tight with JPEG at `quality` (0..9).
  /// Throws std::runtime_error when the connection or the handshake fails.
  RfbTestClient(const std::string& host, int port, int quality = 8, UpdateMode mode = UpdateMode::kRequests);
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
  /// Sends raw bytes as they are (a whole client message, or a malformed one).
  bool send_raw(const std::vector<std::uint8_t>& bytes);

  /// kContinuous: whether ContinuousUpdates are on (enabled, and not ended by the server since).
  [[nodiscard]] bool continuous() const { return continuous_; }
  /// EndOfContinuousUpdates messages received.
  [[nodiscard]] int end_of_continuous_updates() const { return end_of_continuous_; }
  /// Server fences answered (every one had the Request bit; one without it counts in bad_fences()).
  [[nodiscard]] int fences_answered() const { return fences_answered_; }
  /// Server fences without the Request bit or with a payload over 64 bytes (noVNC fails on those).
  [[nodiscard]] int bad_fences() const { return bad_fences_; }
  /// kContinuous: asks the server to stop pushing (EnableContinuousUpdates with enable 0).
  void disable_continuous();

 private:
  static void on_update_finished(_rfbClient* client);
  friend struct StreamingExtension;
  UpdateMode mode_ = UpdateMode::kRequests;
  bool continuous_ = false;
  int end_of_continuous_ = 0;
  int fences_answered_ = 0;
  int bad_fences_ = 0;
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
