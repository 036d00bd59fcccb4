// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's clients (RfbTestClient and H264RfbClient behind NetClient) and picture measures.
#include "network_clients.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "h264_rfb_client.hpp"
#include "rfb_test_client.hpp"

namespace rfbsim::bench {

const char* client_name(ClientKind kind) {
  switch (kind) {
    case ClientKind::kFbur: return "fbur";
    case ClientKind::kCu: return "cu";
    case ClientKind::kH264: return "h264";
  }
  return "?";
}

ClientKind parse_client(const std::string& name) {
  for (const ClientKind kind : {ClientKind::kFbur, ClientKind::kCu, ClientKind::kH264}) {
    if (name == client_name(kind)) return kind;
  }
  throw std::invalid_argument("unknown client '" + name + "' (fbur, cu or h264)");
}

const char* codec_for(ClientKind kind) { return kind == ClientKind::kH264 ? "h264" : "jpeg"; }

namespace {

// libvncclient, asking for each update or with ContinuousUpdates.
class TightClient final : public NetClient {
 public:
  TightClient(int port, test::UpdateMode mode) : client_("127.0.0.1", port, 8, mode) {}
  bool pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) override {
    return client_.pump_until(done, timeout);
  }
  [[nodiscard]] std::uint64_t updates() const override { return client_.updates(); }
  [[nodiscard]] bool connected() const override { return client_.connected(); }
  [[nodiscard]] FrameView frame() const override { return client_.frame(); }
  void send_key(std::uint32_t keysym, bool down) override { client_.send_key(keysym, down); }

 private:
  test::RfbTestClient client_;
};

// The H.264 client with noVNC's defaults (CU + Fence, no Tight).
class H264Client final : public NetClient {
 public:
  explicit H264Client(int port) : client_("127.0.0.1", port) {}
  bool pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) override {
    return client_.pump_until(done, timeout);
  }
  [[nodiscard]] std::uint64_t updates() const override { return client_.updates(); }
  [[nodiscard]] bool connected() const override { return client_.connected(); }
  [[nodiscard]] FrameView frame() const override { return client_.frame(); }
  void send_key(std::uint32_t keysym, bool down) override { client_.send_key(keysym, down); }
  [[nodiscard]] std::uint64_t h264_bytes() const override { return client_.h264_bytes(); }
  [[nodiscard]] std::uint64_t decode_errors() const override { return client_.decode_errors(); }

 private:
  test::H264RfbClient client_;
};

// BT.601 luma of an RGBA pixel, 0..255.
inline double luma(const std::uint8_t* p) { return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]; }

}  // namespace

std::unique_ptr<NetClient> connect_client(ClientKind kind, int port, std::chrono::milliseconds timeout) {
  std::unique_ptr<NetClient> client;
  switch (kind) {
    case ClientKind::kFbur: client = std::make_unique<TightClient>(port, test::UpdateMode::kRequests); break;
    case ClientKind::kCu: client = std::make_unique<TightClient>(port, test::UpdateMode::kContinuous); break;
    case ClientKind::kH264: client = std::make_unique<H264Client>(port); break;
  }
  const std::uint64_t before = client->updates();
  if (!client->pump_until([&] { return client->updates() > before; }, timeout)) {
    throw std::runtime_error(std::string("no first update for the ") + client_name(kind) + " client");
  }
  return client;
}

double sampled_mad(const FrameView& a, const FrameView& b) {
  if (a.width != b.width || a.height != b.height) return std::numeric_limits<double>::infinity();
  std::uint64_t sum = 0;
  std::uint64_t count = 0;
  for (int y = 0; y < a.height; y += 2) {
    const std::uint8_t* ra = a.row(y);
    const std::uint8_t* rb = b.row(y);
    for (int x = 0; x < a.width; x += 2) {
      for (int c = 0; c < 3; ++c) sum += static_cast<std::uint64_t>(std::abs(int{ra[x * 4 + c]} - int{rb[x * 4 + c]}));
      count += 3;
    }
  }
  return count == 0 ? 0.0 : static_cast<double>(sum) / static_cast<double>(count);
}

void PictureCopy::assign(const FrameView& frame) {
  width_ = frame.width;
  height_ = frame.height;
  const std::size_t row = static_cast<std::size_t>(frame.width) * 4U;
  pixels_.resize(row * static_cast<std::size_t>(frame.height));
  for (int y = 0; y < frame.height; ++y) {
    std::memcpy(pixels_.data() + row * static_cast<std::size_t>(y), frame.row(y), row);
  }
}

double luma_ssim(const FrameView& a, const FrameView& b) {
  if (a.width != b.width || a.height != b.height || a.width < 8 || a.height < 8) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Sums over 4x4 blocks of x, y, x^2, y^2 and xy; a window is 2x2 blocks, so windows step 4 pixels.
  const int bw = a.width / 4;
  const int bh = a.height / 4;
  struct Sums {
    double x = 0, y = 0, xx = 0, yy = 0, xy = 0;
  };
  std::vector<Sums> blocks(static_cast<std::size_t>(bw) * static_cast<std::size_t>(bh));
  for (int py = 0; py < bh * 4; ++py) {
    const std::uint8_t* ra = a.row(py);
    const std::uint8_t* rb = b.row(py);
    Sums* line = blocks.data() + static_cast<std::size_t>(py / 4) * static_cast<std::size_t>(bw);
    for (int px = 0; px < bw * 4; ++px) {
      const double x = luma(ra + px * 4);
      const double y = luma(rb + px * 4);
      Sums& s = line[px / 4];
      s.x += x;
      s.y += y;
      s.xx += x * x;
      s.yy += y * y;
      s.xy += x * y;
    }
  }
  // The usual constants for 8-bit data: (0.01 * 255)^2 and (0.03 * 255)^2.
  constexpr double kC1 = 6.5025;
  constexpr double kC2 = 58.5225;
  constexpr double kN = 64.0;
  double total = 0.0;
  int windows = 0;
  for (int wy = 0; wy + 1 < bh; ++wy) {
    for (int wx = 0; wx + 1 < bw; ++wx) {
      Sums w;
      for (const int dy : {0, 1}) {
        for (const int dx : {0, 1}) {
          const Sums& s = blocks[static_cast<std::size_t>(wy + dy) * static_cast<std::size_t>(bw) +
                                 static_cast<std::size_t>(wx + dx)];
          w.x += s.x;
          w.y += s.y;
          w.xx += s.xx;
          w.yy += s.yy;
          w.xy += s.xy;
        }
      }
      const double mx = w.x / kN;
      const double my = w.y / kN;
      const double vx = w.xx / kN - mx * mx;
      const double vy = w.yy / kN - my * my;
      const double cov = w.xy / kN - mx * my;
      total += ((2 * mx * my + kC1) * (2 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
      ++windows;
    }
  }
  return total / windows;
}

}  // namespace rfbsim::bench
