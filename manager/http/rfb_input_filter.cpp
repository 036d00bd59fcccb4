// SPDX-License-Identifier: GPL-2.0-or-later
// Framing of the RFB client-to-server stream (RFC 6143 and the community extensions noVNC uses).
#include "http/rfb_input_filter.hpp"

#include <algorithm>

namespace rfbsim::manager {

namespace {

// Client message types (RFC 6143 7.5 and the rfbproto registry).
constexpr unsigned kSetPixelFormat = 0;
constexpr unsigned kSetEncodings = 2;
constexpr unsigned kFramebufferUpdateRequest = 3;
constexpr unsigned kKeyEvent = 4;
constexpr unsigned kPointerEvent = 5;
constexpr unsigned kClientCutText = 6;
constexpr unsigned kEnableContinuousUpdates = 150;
constexpr unsigned kFence = 248;
constexpr unsigned kSetDesktopSize = 251;
constexpr unsigned kQemu = 255;
constexpr unsigned kQemuExtendedKeyEvent = 0;

// Security types a client may choose (RFC 6143 7.2).
constexpr unsigned kSecurityNone = 1;
constexpr unsigned kSecurityVncAuth = 2;

constexpr std::size_t kVersionSize = 12;      // "RFB xxx.yyy\n"
constexpr std::size_t kVncAuthResponse = 16;  // the DES-encrypted challenge

unsigned byte_at(const std::string& bytes, std::size_t at) { return static_cast<unsigned char>(bytes[at]); }

std::uint32_t big_endian(const std::string& bytes, std::size_t at, std::size_t count) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < count; ++i) value = (value << 8) | byte_at(bytes, at + i);
  return value;
}

bool is_digit(char ch) { return ch >= '0' && ch <= '9'; }

}  // namespace

std::string RfbInputFilter::forward(std::string_view chunk) {
  std::string out;
  std::size_t at = 0;
  while (at < chunk.size() && !failed()) {
    // Inside a unit whose size is known: stream the rest of it, passed or dropped, without buffering it.
    if (rest_ > 0) {
      const std::size_t count = std::min(rest_, chunk.size() - at);
      if (rest_passes_) out.append(chunk.substr(at, count));
      at += count;
      rest_ -= count;
      continue;
    }
    // The start of a unit: gather it byte by byte until its size is known (at most 12 bytes).
    head_.push_back(chunk[at++]);
    const Framing framing = frame_head();
    if (failed() || !framing.complete) continue;
    if (framing.pass) {
      out += head_;
    } else {
      ++dropped_;
    }
    rest_ = framing.size - head_.size();
    rest_passes_ = framing.pass;
    head_.clear();
  }
  return out;
}

RfbInputFilter::Framing RfbInputFilter::frame_head() {
  switch (phase_) {
    case Phase::kVersion: {
      if (head_.size() < kVersionSize) return {};
      // "RFB 003.008\n". Minor versions below 7 mean 3.3 (RFC 6143 7.1.1: 3.5 is to be read as 3.3).
      const bool well_formed = head_.compare(0, 4, "RFB ") == 0 && is_digit(head_[4]) && is_digit(head_[5]) &&
                               is_digit(head_[6]) && head_[7] == '.' && is_digit(head_[8]) &&
                               is_digit(head_[9]) && is_digit(head_[10]) && head_[11] == '\n';
      if (!well_formed) return fail("not an RFB protocol version");
      if (head_.compare(4, 3, "003") != 0) return fail("unsupported RFB major version");
      version_3_3_ = std::stoi(head_.substr(8, 3)) < 7;
      // With 3.3 the server decides the security type alone; rfbsim's sessions have no password, so None.
      phase_ = version_3_3_ ? Phase::kClientInit : Phase::kSecurityType;
      return {true, kVersionSize, true};
    }
    case Phase::kSecurityType: {
      const unsigned type = byte_at(head_, 0);
      if (type == kSecurityNone) {
        phase_ = Phase::kClientInit;
      } else if (type == kSecurityVncAuth) {
        phase_ = Phase::kVncAuthResponse;
      } else {
        return fail("RFB security type " + std::to_string(type) + " is not supported for watching");
      }
      return {true, 1, true};
    }
    case Phase::kVncAuthResponse:
      phase_ = Phase::kClientInit;
      return {true, kVncAuthResponse, true};
    case Phase::kClientInit:
      // Always shared: an exclusive watcher would make a server that honours the flag drop the participant.
      head_[0] = '\x01';
      phase_ = Phase::kMessages;
      return {true, 1, true};
    case Phase::kMessages:
      return frame_message();
  }
  return fail("internal error");
}

RfbInputFilter::Framing RfbInputFilter::frame_message() {
  const unsigned type = byte_at(head_, 0);
  switch (type) {
    case kSetPixelFormat: return {true, 20, true};
    case kSetEncodings:
      // type, padding, number-of-encodings (U16), then one S32 per encoding.
      if (head_.size() < 4) return {};
      return {true, 4 + 4 * std::size_t{big_endian(head_, 2, 2)}, true};
    case kFramebufferUpdateRequest: return {true, 10, true};
    case kKeyEvent: return {true, 8, false};
    case kPointerEvent: return {true, 6, false};
    case kClientCutText: {
      // type, 3 padding, length (S32), text. The extended clipboard sends a negative length: its magnitude
      // counts the bytes that follow.
      if (head_.size() < 8) return {};
      const auto length = static_cast<std::int32_t>(big_endian(head_, 4, 4));
      const std::int64_t magnitude = length < 0 ? -std::int64_t{length} : std::int64_t{length};
      if (static_cast<std::uint64_t>(magnitude) > kMaxCutText) return fail("clipboard text too long");
      return {true, 8 + static_cast<std::size_t>(magnitude), false};
    }
    case kEnableContinuousUpdates: return {true, 10, true};
    case kFence: {
      // type, 3 padding, flags (U32), length (U8), payload.
      if (head_.size() < 9) return {};
      const std::size_t length = byte_at(head_, 8);
      if (length > kMaxFencePayload) return fail("fence payload too long");
      return {true, 9 + length, true};
    }
    case kSetDesktopSize:
      // type, padding, width, height, number-of-screens (U8), padding, then 16 bytes per screen.
      if (head_.size() < 8) return {};
      return {true, 8 + 16 * std::size_t{byte_at(head_, 6)}, true};
    case kQemu: {
      // type, submessage type, then the submessage; only the extended key event (12 bytes in all) is known.
      if (head_.size() < 2) return {};
      const unsigned subtype = byte_at(head_, 1);
      if (subtype == kQemuExtendedKeyEvent) return {true, 12, false};
      return fail("unknown QEMU client message " + std::to_string(subtype));
    }
    default: return fail("unknown RFB client message type " + std::to_string(type));
  }
}

RfbInputFilter::Framing RfbInputFilter::fail(std::string reason) {
  failure_ = std::move(reason);
  head_.clear();
  return {};
}

}  // namespace rfbsim::manager
