// SPDX-License-Identifier: GPL-2.0-or-later
// ContinuousUpdates and Fence end to end: a libvncclient client that speaks them (tests/support's
// UpdateMode::kContinuous) against the in-process server, directly and through the link emulator.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include "eventually.hpp"
#include "link_emulator.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/server.hpp"

using namespace std::chrono_literals;
using rfbsim::test::eventually;
using rfbsim::test::RfbTestClient;
using rfbsim::test::UpdateMode;

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

// Submits frames at about 30 per second from its own thread, as a simulator would, until destroyed.
// Each frame is noise (so every update is large) with a solid centre of the frame's colour index.
class FrameSource {
 public:
  explicit FrameSource(rfbsim::Server& server) : server_(server), thread_([this] { run(); }) {}
  ~FrameSource() {
    stop_ = true;
    thread_.join();
  }
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;

  int submitted() const { return submitted_.load(); }

 private:
  void run() {
    std::vector<std::uint8_t> pixels(static_cast<std::size_t>(kWidth) * kHeight * 4U);
    std::mt19937 noise(1);
    while (!stop_) {
      const int k = submitted_.load();
      for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
          std::uint8_t* p = &pixels[(static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)) * 4U];
          const bool centre = std::abs(x - kWidth / 2) < 20 && std::abs(y - kHeight / 2) < 20;
          const auto v = noise();
          p[0] = centre ? static_cast<std::uint8_t>(k * 37) : static_cast<std::uint8_t>(v);
          p[1] = centre ? static_cast<std::uint8_t>(255 - k * 37) : static_cast<std::uint8_t>(v >> 8);
          p[2] = centre ? 128 : static_cast<std::uint8_t>(v >> 16);
          p[3] = 255;
        }
      }
      server_.submit(rfbsim::FrameView{pixels.data(), kWidth, kHeight, 0});
      ++submitted_;
      std::this_thread::sleep_for(33ms);
    }
  }

  rfbsim::Server& server_;
  std::atomic<bool> stop_{false};
  std::atomic<int> submitted_{0};
  std::thread thread_;
};

rfbsim::ServerOptions streaming_server() {
  rfbsim::ServerOptions options;
  options.width = kWidth;
  options.height = kHeight;
  return options;
}

// The server's view of the client with `id`, once published.
std::optional<rfbsim::ClientStreamStatus> stream_of(const rfbsim::Server& server, int id) {
  for (const auto& stream : server.client_streams()) {
    if (stream.id == id) return stream;
  }
  return std::nullopt;
}

}  // namespace

TEST_CASE("a ContinuousUpdates client gets frames pushed while it sends no update request", "[streaming]") {
  rfbsim::Server server(streaming_server());
  FrameSource frames(server);
  RfbTestClient client("127.0.0.1", server.port(), 8, UpdateMode::kContinuous);
  REQUIRE(client.pump_until([&] { return client.continuous(); }, 10s));
  // From here on libvncclient may not send a single request (tests/support clears its permission), so
  // every further update was pushed.
  const std::uint64_t before = client.updates();
  CHECK(client.wait_for_updates(20, 20s));
  CHECK(client.updates() >= before + 20);
  CHECK(client.end_of_continuous_updates() == 1);
  CHECK(client.fences_answered() >= 20);  // a ping after every pushed update
  CHECK(client.bad_fences() == 0);
  // The server's view (published a few times a second): pushed, fenced, round trip measured.
  REQUIRE(eventually([&] { return stream_of(server, 1) && stream_of(server, 1)->updates_sent >= 20; }, 5s));
  const auto stream = stream_of(server, 1);
  CHECK(stream->continuous_updates);
  CHECK(stream->fence);
  CHECK(stream->encoding == "tight");
  CHECK(stream->base_rtt_ms >= 0.0);
  CHECK(stream->updates_sent >= 20);
}

TEST_CASE("a requesting client and a ContinuousUpdates client are served side by side", "[streaming]") {
  rfbsim::Server server(streaming_server());
  FrameSource frames(server);
  RfbTestClient plain("127.0.0.1", server.port());
  RfbTestClient pushed("127.0.0.1", server.port(), 8, UpdateMode::kContinuous);
  REQUIRE(pushed.pump_until([&] { return pushed.continuous(); }, 10s));
  for (int round = 0; round < 10; ++round) {
    CHECK(plain.wait_for_updates(1, 10s));
    CHECK(pushed.wait_for_updates(1, 10s));
  }
  CHECK(plain.end_of_continuous_updates() == 0);  // it never offered: nothing was announced to it
  CHECK(plain.fences_answered() == 0);
  REQUIRE(eventually([&] { return server.client_streams().size() == 2; }, 5s));
  CHECK_FALSE(stream_of(server, 1)->continuous_updates);
  CHECK(stream_of(server, 2)->continuous_updates);
}

TEST_CASE("disabling ContinuousUpdates goes back to requested updates", "[streaming]") {
  rfbsim::Server server(streaming_server());
  FrameSource frames(server);
  RfbTestClient client("127.0.0.1", server.port(), 8, UpdateMode::kContinuous);
  REQUIRE(client.pump_until([&] { return client.continuous(); }, 10s));
  CHECK(client.wait_for_updates(3, 10s));
  client.disable_continuous();
  // The server confirms with a second EndOfContinuousUpdates; the client then requests again.
  REQUIRE(client.pump_until([&] { return client.end_of_continuous_updates() == 2; }, 10s));
  CHECK_FALSE(client.continuous());
  CHECK(client.wait_for_updates(5, 10s));
  REQUIRE(eventually([&] { return stream_of(server, 1) && !stream_of(server, 1)->continuous_updates; }, 5s));
}

TEST_CASE("over a slow link frames are held back and coalesce, and the newest picture arrives", "[streaming][waits]") {
  rfbsim::Server server(streaming_server());
  // 200 ms round trip and 2 Mbit/s: a 320x240 noise frame (~100 KB as JPEG) takes ~0.4 s to cross, so
  // most of the 30 frames a second must be held back and merged into the next update.
  rfbsim::test::LinkEmulator link("127.0.0.1", server.port(), rfbsim::test::link_profile(200ms, 2.0));
  RfbTestClient client("127.0.0.1", link.port(), 8, UpdateMode::kContinuous);
  REQUIRE(client.pump_until([&] { return client.continuous(); }, 10s));
  int submitted = 0;
  {
    FrameSource frames(server);
    client.pump_until([] { return false; }, 4s);
    submitted = frames.submitted();
  }
  CHECK(client.updates() < static_cast<std::uint64_t>(submitted));
  REQUIRE(eventually([&] { return stream_of(server, 1) && stream_of(server, 1)->updates_held > 0; }, 5s));
  // Once the source stops, the last frame's centre colour reaches the client: latest wins, none lost.
  const int last = submitted - 1;
  const auto r = static_cast<std::uint8_t>(last * 37);
  const auto g = static_cast<std::uint8_t>(255 - last * 37);
  const auto shows_last = [&] {
    const rfbsim::FrameView view = client.frame();
    const std::uint8_t* p = view.row(kHeight / 2) + static_cast<std::size_t>(kWidth / 2) * 4U;
    return std::abs(int{p[0]} - r) <= 8 && std::abs(int{p[1]} - g) <= 8;
  };
  CHECK(client.pump_until(shows_last, 15s));
  CHECK(client.bad_fences() == 0);
}
