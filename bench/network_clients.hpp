// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's picture clients behind one face, and the picture measures it judges them by.
//
// Three kinds of client, as a participant's viewer may be:
//   fbur  libvncclient asking for each update (RfbTestClient, UpdateMode::kRequests): at most one update per
//         round trip; served Tight JPEG (sim_rfb --codec jpeg);
//   cu    libvncclient with ContinuousUpdates and Fence (UpdateMode::kContinuous): the server pushes, paced
//         by its congestion control; Tight JPEG (--codec jpeg);
//   h264  H264RfbClient (CU + Fence, decodes encoding 50 with libavcodec, as noVNC >= 1.6 does); --codec h264.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim::bench {

/// Which viewer a cell runs.
enum class ClientKind { kFbur, kCu, kH264 };

/// "fbur", "cu" or "h264".
const char* client_name(ClientKind kind);
/// The kind named `name`; throws std::invalid_argument for another name.
ClientKind parse_client(const std::string& name);
/// The sim_rfb `--codec` value the kind is measured against: "jpeg" (fbur, cu) or "h264".
const char* codec_for(ClientKind kind);

/// A connected picture client. One thread calls everything.
class NetClient {
 public:
  virtual ~NetClient() = default;
  /// Handles server messages until `done()` holds (checked at least after every complete update), the
  /// connection fails or `timeout` passes; returns whether `done()` held.
  virtual bool pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) = 0;
  /// Complete framebuffer updates received so far.
  [[nodiscard]] virtual std::uint64_t updates() const = 0;
  /// Whether the connection still works.
  [[nodiscard]] virtual bool connected() const = 0;
  /// The client's picture, RGBA (alpha undefined), valid until the next pump_until().
  [[nodiscard]] virtual FrameView frame() const = 0;
  /// Sends a KeyEvent (X11 keysym).
  virtual void send_key(std::uint32_t keysym, bool down) = 0;
  /// H.264 payload bytes received so far (0 for a Tight client).
  [[nodiscard]] virtual std::uint64_t h264_bytes() const { return 0; }
  /// H.264 pictures that failed to decode so far (0 for a Tight client).
  [[nodiscard]] virtual std::uint64_t decode_errors() const { return 0; }
};

/// Connects a client of `kind` to 127.0.0.1:`port` and waits for its first complete update (up to `timeout`).
/// Throws std::runtime_error when the connection, the handshake or the first update fails.
std::unique_ptr<NetClient> connect_client(ClientKind kind, int port, std::chrono::milliseconds timeout);

/// Mean absolute difference per colour channel (0..255) of two equal-size RGB(A) pictures, over every second
/// pixel of every second row (a quarter of the work of a full compare; the pictures compared here differ,
/// when they do, across most of the view). Infinity when the sizes differ.
double sampled_mad(const FrameView& a, const FrameView& b);

/// A copy of a picture that outlives the client's buffer.
class PictureCopy {
 public:
  /// Copies `frame`'s pixels (tightly packed) into this copy.
  void assign(const FrameView& frame);
  [[nodiscard]] FrameView view() const { return FrameView{pixels_.data(), width_, height_, 0}; }
  [[nodiscard]] bool empty() const { return pixels_.empty(); }

 private:
  std::vector<std::uint8_t> pixels_;
  int width_ = 0;
  int height_ = 0;
};

/// SSIM (Wang et al. 2004) of the luma (BT.601) of two equal-size RGB(A) pictures, over 8x8 windows placed
/// every 4 pixels, averaged: 1 = identical. NaN when the sizes differ or a picture is smaller than 8x8.
double luma_ssim(const FrameView& a, const FrameView& b);

}  // namespace rfbsim::bench
