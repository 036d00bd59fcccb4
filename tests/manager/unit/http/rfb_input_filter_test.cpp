// SPDX-License-Identifier: GPL-2.0-or-later
// RfbInputFilter on hand-made RFB client streams: exact bytes out, for every way a stream can be split.
#include <catch2/catch.hpp>

#include <cstdint>
#include <initializer_list>
#include <string>

#include "http/rfb_input_filter.hpp"

using rfbsim::manager::RfbInputFilter;

namespace {

std::string bytes(std::initializer_list<int> values) {
  std::string out;
  for (const int value : values) out.push_back(static_cast<char>(value));
  return out;
}

std::string u16(unsigned value) {
  return bytes({static_cast<int>((value >> 8) & 0xff), static_cast<int>(value & 0xff)});
}

std::string u32(std::uint32_t value) {
  return bytes({static_cast<int>(value >> 24), static_cast<int>((value >> 16) & 0xff),
                static_cast<int>((value >> 8) & 0xff), static_cast<int>(value & 0xff)});
}

// The client's side of a 3.8 handshake with security None and a shared ClientInit.
const std::string kHandshake38 = std::string("RFB 003.008\n") + bytes({1}) + bytes({1});

// Messages that pass (views and requests) and messages that are dropped (input), each exactly as sent.
const std::string kSetPixelFormat = bytes({0, 0, 0, 0, 32, 24, 0, 1}) + u16(255) + u16(255) + u16(255) +
                                    bytes({16, 8, 0, 0, 0, 0});
const std::string kSetEncodings = bytes({2, 0}) + u16(3) + u32(7) + u32(static_cast<std::uint32_t>(-32)) +
                                  u32(static_cast<std::uint32_t>(-223));
const std::string kUpdateRequest = bytes({3, 1}) + u16(0) + u16(0) + u16(640) + u16(480);
const std::string kContinuousUpdates = bytes({150, 1}) + u16(0) + u16(0) + u16(640) + u16(480);
const std::string kFence = bytes({248, 0, 0, 0}) + u32(0x80000003u) + bytes({4, 'a', 'b', 'c', 'd'});
const std::string kSetDesktopSize = bytes({251, 0}) + u16(800) + u16(600) + bytes({1, 0}) + u32(7) + u16(0) +
                                    u16(0) + u16(800) + u16(600) + u32(0);
const std::string kKeyDown = bytes({4, 1, 0, 0}) + u32('w');
const std::string kPointer = bytes({5, 1}) + u16(100) + u16(200);
const std::string kCutText = bytes({6, 0, 0, 0}) + u32(5) + "hello";
// The extended clipboard's negative length: -3 here, three bytes follow.
const std::string kExtendedCutText = bytes({6, 0, 0, 0}) + u32(static_cast<std::uint32_t>(-3)) + bytes({1, 2, 3});
const std::string kQemuKey = bytes({255, 0}) + u16(1) + u32('w') + u32(17);

// A session as noVNC runs it: handshake, set-up, requests, and input between them.
const std::string kStream = kHandshake38 + kSetPixelFormat + kSetEncodings + kUpdateRequest + kKeyDown + kPointer +
                            kCutText + kUpdateRequest + kQemuKey + kContinuousUpdates + kFence + kSetDesktopSize +
                            kExtendedCutText + kUpdateRequest;
const std::string kPassed = kHandshake38 + kSetPixelFormat + kSetEncodings + kUpdateRequest + kUpdateRequest +
                            kContinuousUpdates + kFence + kSetDesktopSize + kUpdateRequest;
constexpr std::uint64_t kDroppedInStream = 5;

std::string filter_all(const std::string& stream) {
  RfbInputFilter filter;
  std::string out = filter.forward(stream);
  CHECK_FALSE(filter.failed());
  return out;
}

// Feeds `messages` after a 3.8 handshake; returns the filter for inspection and what it passed after the handshake.
std::string after_handshake(RfbInputFilter& filter, const std::string& messages) {
  REQUIRE(filter.forward(kHandshake38) == kHandshake38);
  return filter.forward(messages);
}

}  // namespace

TEST_CASE("the filter passes the handshake, views and requests, and drops keys, pointer and clipboard") {
  RfbInputFilter filter;
  CHECK(filter.forward(kStream) == kPassed);
  CHECK_FALSE(filter.failed());
  CHECK(filter.failure().empty());
  CHECK(filter.dropped_messages() == kDroppedInStream);
}

TEST_CASE("the filter's output does not depend on how the stream is split") {
  SECTION("one byte at a time") {
    RfbInputFilter filter;
    std::string out;
    for (const char byte : kStream) out += filter.forward(std::string_view(&byte, 1));
    CHECK(out == kPassed);
    CHECK(filter.dropped_messages() == kDroppedInStream);
  }
  SECTION("split in three at every pair of boundaries") {
    // Every chunk boundary falls inside a handshake unit, a header, a length field or a body somewhere.
    const std::string_view stream = kStream;
    for (std::size_t first = 0; first <= stream.size(); ++first) {
      for (std::size_t second = first; second <= stream.size(); ++second) {
        RfbInputFilter filter;
        std::string out = filter.forward(stream.substr(0, first));
        out += filter.forward(stream.substr(first, second - first));
        out += filter.forward(stream.substr(second));
        if (out != kPassed || filter.failed() || filter.dropped_messages() != kDroppedInStream) {
          FAIL("split at " << first << " and " << second << ": " << filter.failure());
        }
      }
    }
  }
  SECTION("empty chunks change nothing") {
    RfbInputFilter filter;
    CHECK(filter.forward("").empty());
    CHECK(filter.forward(kStream) == kPassed);
    CHECK(filter.forward("").empty());
  }
}

TEST_CASE("ClientInit always asks for a shared session") {
  const std::string exclusive = std::string("RFB 003.008\n") + bytes({1}) + bytes({0});
  CHECK(filter_all(exclusive + kUpdateRequest) == kHandshake38 + kUpdateRequest);
  const std::string shared_other = std::string("RFB 003.008\n") + bytes({1}) + bytes({7});
  CHECK(filter_all(shared_other) == kHandshake38);
}

TEST_CASE("the handshake variants of 3.3, 3.7 and VNC authentication are framed") {
  SECTION("3.3: the server chose the security type, so ClientInit comes next") {
    const std::string hello = std::string("RFB 003.003\n") + bytes({1});
    CHECK(filter_all(hello + kKeyDown + kUpdateRequest) == hello + kUpdateRequest);
  }
  SECTION("3.5, which clients once sent, is 3.3") {
    const std::string hello = std::string("RFB 003.005\n") + bytes({1});
    CHECK(filter_all(hello + kPointer + kUpdateRequest) == hello + kUpdateRequest);
  }
  SECTION("3.7 chooses a security type as 3.8 does") {
    const std::string hello = std::string("RFB 003.007\n") + bytes({1, 1});
    CHECK(filter_all(hello + kKeyDown + kUpdateRequest) == hello + kUpdateRequest);
  }
  SECTION("VNC authentication: the 16-byte response passes whole, even bytes that look like messages") {
    const std::string response = bytes({4, 1, 0, 0, 0, 0, 0, 'w', 5, 1, 0, 1, 0, 1, 6, 0});
    const std::string hello = std::string("RFB 003.008\n") + bytes({2}) + response + bytes({1});
    CHECK(filter_all(hello + kKeyDown + kUpdateRequest) == hello + kUpdateRequest);
  }
}

TEST_CASE("variable-length messages are framed by their length fields") {
  RfbInputFilter filter;
  SECTION("no encodings, no screens, an empty fence and empty clipboard text") {
    const std::string none = bytes({2, 0}) + u16(0);
    const std::string no_screens = bytes({251, 0}) + u16(800) + u16(600) + bytes({0, 0});
    const std::string empty_fence = bytes({248, 0, 0, 0}) + u32(0) + bytes({0});
    const std::string empty_text = bytes({6, 0, 0, 0}) + u32(0);
    CHECK(after_handshake(filter, none + no_screens + empty_text + empty_fence + kUpdateRequest) ==
          none + no_screens + empty_fence + kUpdateRequest);
    CHECK(filter.dropped_messages() == 1);
  }
  SECTION("a fence carries at most 64 bytes") {
    const std::string fence = bytes({248, 0, 0, 0}) + u32(0) + bytes({64}) + std::string(64, 'x');
    CHECK(after_handshake(filter, fence + kUpdateRequest) == fence + kUpdateRequest);
    CHECK(filter.forward(bytes({248, 0, 0, 0}) + u32(0) + bytes({65})).empty());
    CHECK(filter.failure() == "fence payload too long");
  }
  SECTION("clipboard text up to 1 MiB is dropped as it streams; longer fails") {
    const auto max = static_cast<std::uint32_t>(RfbInputFilter::kMaxCutText);
    const std::string text(RfbInputFilter::kMaxCutText, 'x');
    CHECK(after_handshake(filter, bytes({6, 0, 0, 0}) + u32(max)).empty());
    bool all_dropped = true;
    for (std::size_t at = 0; at < text.size(); at += 4096) {
      all_dropped = all_dropped && filter.forward(std::string_view(text).substr(at, 4096)).empty();
    }
    CHECK(all_dropped);
    CHECK(filter.forward(kUpdateRequest) == kUpdateRequest);
    CHECK(filter.forward(bytes({6, 0, 0, 0}) + u32(0u - max) + text + kUpdateRequest) == kUpdateRequest);
    CHECK_FALSE(filter.failed());
    CHECK(filter.dropped_messages() == 2);
    CHECK(filter.forward(bytes({6, 0, 0, 0}) + u32(max + 1)).empty());
    CHECK(filter.failure() == "clipboard text too long");
  }
  SECTION("the most negative length does not overflow") {
    CHECK(after_handshake(filter, bytes({6, 0, 0, 0}) + u32(0x80000000u)).empty());
    CHECK(filter.failure() == "clipboard text too long");
  }
}

TEST_CASE("a stream the filter cannot frame fails it, and nothing passes after that") {
  RfbInputFilter filter;
  SECTION("an unknown message type: what came before it in the chunk still passes") {
    CHECK(after_handshake(filter, kUpdateRequest + bytes({7, 0, 0, 0}) + kUpdateRequest) == kUpdateRequest);
    CHECK(filter.failed());
    CHECK(filter.failure() == "unknown RFB client message type 7");
    CHECK(filter.forward(kUpdateRequest).empty());
  }
  SECTION("xvp (shut down the machine) is no view") {
    CHECK(after_handshake(filter, bytes({250, 0, 1, 2})).empty());
    CHECK(filter.failure() == "unknown RFB client message type 250");
  }
  SECTION("QEMU messages other than the extended key event") {
    CHECK(after_handshake(filter, bytes({255, 1}) + u16(0)).empty());
    CHECK(filter.failure() == "unknown QEMU client message 1");
  }
  SECTION("not an RFB version") {
    CHECK(filter.forward("GET / HTTP/1.1\r\n").empty());
    CHECK(filter.failure() == "not an RFB protocol version");
  }
  SECTION("another major version") {
    CHECK(filter.forward("RFB 004.001\n").empty());
    CHECK(filter.failure() == "unsupported RFB major version");
  }
  SECTION("a security type other than None and VNC authentication") {
    CHECK(filter.forward(std::string("RFB 003.008\n") + bytes({16})) == "RFB 003.008\n");
    CHECK(filter.failure() == "RFB security type 16 is not supported for watching");
  }
  CHECK(filter.failure().size() <= 123);  // it becomes a WebSocket close reason
}
