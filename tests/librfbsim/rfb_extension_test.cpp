// SPDX-License-Identifier: GPL-2.0-or-later
// The bytes of the streaming extensions (Fence, ContinuousUpdates, the H.264 rectangle), against rfbproto.
#include "rfb_extension.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <vector>

using namespace rfbsim::detail;

TEST_CASE("fence_message lays out type, padding, flags big-endian, length and payload", "[rfb_extension]") {
  const std::array<std::uint8_t, 2> payload{'a', 'b'};
  const auto bytes = fence_message(kFenceRequest | kFenceBlockBefore, payload);
  const std::vector<std::uint8_t> expected{248, 0, 0, 0, 0x80, 0, 0, 0x01, 2, 'a', 'b'};
  CHECK(bytes == expected);
}

TEST_CASE("fence_message never sends more than 64 payload bytes", "[rfb_extension]") {
  const std::vector<std::uint8_t> payload(100, 7);
  const auto bytes = fence_message(kFenceRequest, payload);
  CHECK(bytes.size() == 9 + 64);
  CHECK(bytes[8] == 64);
}

TEST_CASE("a fence answer clears Request, SyncNext and unknown bits and keeps the block flags", "[rfb_extension]") {
  CHECK(fence_answer_flags(kFenceRequest | kFenceBlockBefore) == kFenceBlockBefore);
  CHECK(fence_answer_flags(kFenceRequest | kFenceBlockAfter | kFenceSyncNext) == kFenceBlockAfter);
  CHECK(fence_answer_flags(kFenceRequest | 0x00F0'0000U) == 0U);
}

TEST_CASE("parse_fence_head reads flags and length, and refuses payloads over 64 bytes", "[rfb_extension]") {
  const std::array<std::uint8_t, 8> ok{0, 0, 0, 0x80, 0, 0, 0x03, 64};
  const auto head = parse_fence_head(ok);
  REQUIRE(head);
  CHECK(head->flags == (kFenceRequest | kFenceBlockBefore | kFenceBlockAfter));
  CHECK(head->payload_length == 64);
  const std::array<std::uint8_t, 8> too_long{0, 0, 0, 0x80, 0, 0, 0, 65};
  CHECK_FALSE(parse_fence_head(too_long));
}

TEST_CASE("parse_continuous_updates takes an enable inside the framebuffer", "[rfb_extension]") {
  const std::array<std::uint8_t, 9> whole{1, 0, 0, 0, 0, 0x05, 0x00, 0x02, 0xD0};  // 0,0 1280x720
  const auto request = parse_continuous_updates(whole, 1280, 720);
  REQUIRE(request);
  CHECK(request->enable);
  CHECK(request->area.x == 0);
  CHECK(request->area.y == 0);
  CHECK(request->area.w == 1280);
  CHECK(request->area.h == 720);
}

TEST_CASE("parse_continuous_updates refuses an empty area or one past the edge", "[rfb_extension]") {
  const std::array<std::uint8_t, 9> past_right{1, 0, 1, 0, 0, 0x05, 0x00, 0x02, 0xD0};  // x=1 w=1280
  CHECK_FALSE(parse_continuous_updates(past_right, 1280, 720));
  const std::array<std::uint8_t, 9> empty{1, 0, 0, 0, 0, 0, 0, 0x02, 0xD0};
  CHECK_FALSE(parse_continuous_updates(empty, 1280, 720));
  const std::array<std::uint8_t, 9> too_tall{1, 0, 0, 0, 0, 0x05, 0x00, 0xFF, 0xFF};
  CHECK_FALSE(parse_continuous_updates(too_tall, 1280, 720));
}

TEST_CASE("a disable is accepted whatever area it carries", "[rfb_extension]") {
  const std::array<std::uint8_t, 9> disable{0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  const auto request = parse_continuous_updates(disable, 64, 48);
  REQUIRE(request);
  CHECK_FALSE(request->enable);
}

TEST_CASE("end_of_continuous_updates_message is the one type byte", "[rfb_extension]") {
  CHECK(end_of_continuous_updates_message() == std::vector<std::uint8_t>{150});
}

TEST_CASE("h264_update_header: one rectangle of encoding 50 with length and flags", "[rfb_extension]") {
  const auto bytes = h264_update_header(1280, 720, 0x01020304U, kH264ResetContext);
  const std::vector<std::uint8_t> expected{0, 0, 0, 1,               // FramebufferUpdate, pad, 1 rect
                                           0, 0, 0, 0,               // x, y
                                           0x05, 0x00, 0x02, 0xD0,   // 1280 x 720
                                           0, 0, 0, 50,              // encoding 50
                                           1, 2, 3, 4,               // data length
                                           0, 0, 0, 1};              // ResetContext
  CHECK(bytes == expected);
}
