// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <atomic>
#include <thread>
#include <vector>

#include "frame_mailbox.hpp"

using rfbsim::FrameView;
using rfbsim::detail::FrameMailbox;

namespace {
std::vector<std::uint8_t> filled(int w, int h, std::uint8_t value) {
  return std::vector<std::uint8_t>(static_cast<std::size_t>(w * h * 4), value);
}
}  // namespace

TEST_CASE("take returns nothing until a frame is posted - then the newest frame once") {
  FrameMailbox mailbox(4, 2);
  std::vector<std::uint8_t> out;
  CHECK_FALSE(mailbox.take(out));
  const auto first = filled(4, 2, 1);
  const auto second = filled(4, 2, 2);
  mailbox.post({first.data(), 4, 2, 0});
  mailbox.post({second.data(), 4, 2, 0});
  REQUIRE(mailbox.take(out));
  CHECK(out == second);
  CHECK(mailbox.overwritten() == 1);
  CHECK_FALSE(mailbox.take(out));
}

TEST_CASE("strided frames are packed") {
  FrameMailbox mailbox(2, 2);
  std::vector<std::uint8_t> padded(2 * 12, 0);  // stride 12 bytes for 2 pixels of 4
  padded[0] = 10;
  padded[12 + 4] = 20;
  mailbox.post({padded.data(), 2, 2, 12});
  std::vector<std::uint8_t> out;
  REQUIRE(mailbox.take(out));
  REQUIRE(out.size() == 16);
  CHECK(out[0] == 10);
  CHECK(out[8 + 4] == 20);
}

TEST_CASE("a reader never sees a torn frame") {
  // Every posted frame is uniform; a frame mixing two values would be torn.
  constexpr int kW = 64, kH = 64;
  FrameMailbox mailbox(kW, kH);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 0; i < 2000; ++i) {
      const auto frame = filled(kW, kH, static_cast<std::uint8_t>(i));
      mailbox.post({frame.data(), kW, kH, 0});
    }
    done = true;
  });
  std::vector<std::uint8_t> out;
  int taken = 0;
  bool torn = false;
  // Keep reading until the writer is done and its last frame has been taken.
  for (;;) {
    const bool finished = done;
    if (mailbox.take(out)) {
      ++taken;
      for (auto byte : out) torn = torn || byte != out[0];
    } else if (finished) {
      break;
    }
  }
  writer.join();
  CHECK_FALSE(torn);
  CHECK(taken > 0);
}
