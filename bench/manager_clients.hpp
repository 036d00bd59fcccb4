// SPDX-License-Identifier: GPL-2.0-or-later
// bench_manager's clients: an RFB client behind a WebSocket bridge that consumes updates on its own thread
// and records when each arrived, and the fingerprints (hash, thumbnail) that pair two clients' updates of
// one frame.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/frame.hpp"
#include "ws_rfb_bridge.hpp"

namespace rfbsim::bench {

/// A 64-bit hash of a picture's colour (the undefined alpha byte masked off): equal pictures, equal hashes.
std::uint64_t picture_hash(const FrameView& frame);

/// The picture's luma averaged over 4x4-pixel blocks, one byte per block, row by row. Two clients showing the
/// same frame rarely hold identical pixels: each picture keeps its own JPEG history (its first full update,
/// and rectangles grouped by when its requests arrived), but they differ by a few levels of JPEG noise, which
/// the averaging flattens; two consecutive frames of a moving crowd differ by far more (see bench_manager's
/// kSameFrameCells).
std::vector<std::uint8_t> picture_thumb(const FrameView& frame);

/// Thumbnail cells of `a` and `b` that differ by more than JPEG noise (8 levels); counting stops past `limit`,
/// and thumbnails of different sizes are `limit + 1` apart.
int thumb_distance(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, int limit);

/// One complete framebuffer update as a WatchedClient saw it.
struct Arrival {
  Clock::time_point at;             ///< when the update completed at the client
  std::uint64_t hash = 0;           ///< picture_hash of the client's picture after it (0 without fingerprints)
  std::vector<std::uint8_t> thumb;  ///< its picture_thumb (empty without fingerprints)
};

/// An RfbTestClient behind its own WsRfbBridge; construction returns once the RFB handshake is done.
/// start() pumps updates on a thread of its own; counts may be read meanwhile, arrivals after stop().
/// With `fingerprints`, each arrival also carries the picture's hash and thumbnail (a few ms per update).
class WatchedClient {
 public:
  /// Connects through a bridge to `ws_url`, sending `origin`. Throws std::runtime_error when the WebSocket
  /// or the RFB handshake fails (with the WebSocket handshake's status in the message).
  WatchedClient(const std::string& ws_url, const std::string& origin, bool fingerprints);
  /// Stops the pump thread if it runs.
  ~WatchedClient();
  WatchedClient(const WatchedClient&) = delete;
  WatchedClient& operator=(const WatchedClient&) = delete;

  /// Starts pumping updates on a new thread; once only.
  void start();
  /// Stops and joins the pump thread (within about 200 ms); idempotent.
  void stop();
  /// Complete updates received so far (any thread).
  [[nodiscard]] std::uint64_t updates() const { return updates_.load(); }
  /// Every update received while pumping, in order (after stop()).
  [[nodiscard]] const std::vector<Arrival>& arrivals() const { return arrivals_; }
  /// Whether the connection still worked when pumping ended (true until then).
  [[nodiscard]] bool connected() const { return connected_.load(); }

 private:
  static test::RfbTestClient connect(const test::WsRfbBridge& bridge);
  void pump();

  test::WsRfbBridge bridge_;
  test::RfbTestClient client_;
  bool fingerprints_;  // hash and thumbnail each picture
  std::atomic<bool> stopping_{false};
  std::atomic<bool> connected_{true};
  std::atomic<std::uint64_t> updates_{0};
  std::vector<Arrival> arrivals_;  // written by the pump thread only
  std::thread thread_;
};

}  // namespace rfbsim::bench
