// SPDX-License-Identifier: GPL-2.0-or-later
// WatchedClient and the picture fingerprints bench_manager pairs updates with.
#include "manager_clients.hpp"

#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace rfbsim::bench {

namespace {

constexpr int kThumbBlock = 4;   // thumbnail cell: kThumbBlock x kThumbBlock pixels
constexpr int kNoiseLevels = 8;  // JPEG noise between two pictures of one frame, in luma levels

}  // namespace

std::uint64_t picture_hash(const FrameView& frame) {
  constexpr std::uint64_t kColour = 0x00FFFFFF00FFFFFFULL;
  std::uint64_t h = 0x9E3779B97F4A7C15ULL;
  const std::size_t row_bytes = static_cast<std::size_t>(frame.width) * 4U;
  for (int y = 0; y < frame.height; ++y) {
    const std::uint8_t* row = frame.row(y);
    std::size_t i = 0;
    for (; i + 8 <= row_bytes; i += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, row + i, 8);
      h = (h ^ (word & kColour)) * 0x100000001B3ULL;
      h ^= h >> 29;
    }
    if (i < row_bytes) {  // an odd width's last pixel
      std::uint32_t pixel = 0;
      std::memcpy(&pixel, row + i, 4);
      h = (h ^ (pixel & 0x00FFFFFFU)) * 0x100000001B3ULL;
    }
  }
  return h;
}

std::vector<std::uint8_t> picture_thumb(const FrameView& frame) {
  const int tw = frame.width / kThumbBlock;
  const int th = frame.height / kThumbBlock;
  std::vector<std::uint32_t> sum(static_cast<std::size_t>(tw) * static_cast<std::size_t>(th), 0);
  for (int y = 0; y < th * kThumbBlock; ++y) {
    const std::uint8_t* row = frame.row(y);
    std::uint32_t* out = sum.data() + static_cast<std::size_t>(y / kThumbBlock) * static_cast<std::size_t>(tw);
    for (int x = 0; x < tw * kThumbBlock; ++x) {
      const std::uint8_t* p = row + static_cast<std::size_t>(x) * 4U;
      out[x / kThumbBlock] += 2U * p[0] + 5U * p[1] + p[2];  // luma, weights summing to 8
    }
  }
  std::vector<std::uint8_t> thumb(sum.size());
  constexpr std::uint32_t kDivisor = 8U * kThumbBlock * kThumbBlock;
  for (std::size_t i = 0; i < sum.size(); ++i) thumb[i] = static_cast<std::uint8_t>(sum[i] / kDivisor);
  return thumb;
}

// Thumbnail cells that differ by more than kNoiseLevels; counting stops past `limit`.
int thumb_distance(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, int limit) {
  if (a.size() != b.size()) return limit + 1;
  int count = 0;
  for (std::size_t i = 0; i < a.size() && count <= limit; ++i) count += std::abs(int{a[i]} - int{b[i]}) > kNoiseLevels;
  return count;
}

WatchedClient::WatchedClient(const std::string& ws_url, const std::string& origin, bool fingerprints)
    : bridge_(ws_url, origin), client_(connect(bridge_)), fingerprints_(fingerprints) {}

WatchedClient::~WatchedClient() { stop(); }

void WatchedClient::start() {
  thread_ = std::thread([this] { pump(); });
}

void WatchedClient::stop() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
}

test::RfbTestClient WatchedClient::connect(const test::WsRfbBridge& bridge) {
  try {
    return test::RfbTestClient("127.0.0.1", bridge.port());
  } catch (const std::runtime_error& error) {
    const auto last = bridge.last();
    throw std::runtime_error(std::string(error.what()) + " (WebSocket handshake status " +
                             std::to_string(last.handshake_status) + (last.error.empty() ? "" : ", " + last.error) +
                             ")");
  }
}

void WatchedClient::pump() {
  std::uint64_t seen = client_.updates();
  // The arrival time is taken first, as soon as libvncclient has handled the whole update.
  const auto record = [&] {
    if (client_.updates() != seen) {
      const Arrival arrival{Clock::now(), 0, {}};
      seen = client_.updates();
      updates_.store(seen);
      arrivals_.push_back(arrival);
      if (fingerprints_) {
        arrivals_.back().hash = picture_hash(client_.frame());
        arrivals_.back().thumb = picture_thumb(client_.frame());
      }
    }
    return stopping_.load();
  };
  while (!stopping_ && client_.connected()) client_.pump_until(record, std::chrono::milliseconds(200));
  connected_ = client_.connected();
}

}  // namespace rfbsim::bench
