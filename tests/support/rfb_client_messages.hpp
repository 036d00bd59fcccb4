// SPDX-License-Identifier: GPL-2.0-or-later
// Client-to-server RFB messages the test clients build byte by byte (RFC 6143 and the community extensions),
// written from the specification and independent of librfbsim's own encoders, so that a test checks the server
// against the protocol rather than against itself. Shared by RfbTestClient and H264RfbClient.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace rfbsim::test {

/// Appends a big-endian U16; `value` is clamped to 0..65535.
inline void put_u16_clamped(std::vector<std::uint8_t>& out, int value) {
  const auto v = static_cast<std::uint32_t>(std::clamp(value, 0, 65535));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

/// A message of `type` whose body is a U8 flag and an area, U16 x, y, w, h: here the whole width x height
/// framebuffer.
inline std::vector<std::uint8_t> whole_frame_message(std::uint8_t type, bool flag, int width, int height) {
  std::vector<std::uint8_t> out{type, static_cast<std::uint8_t>(flag ? 1 : 0)};
  put_u16_clamped(out, 0);
  put_u16_clamped(out, 0);
  put_u16_clamped(out, width);
  put_u16_clamped(out, height);
  return out;
}

/// EnableContinuousUpdates (150): U8 enable, then the area.
inline std::vector<std::uint8_t> enable_continuous_message(bool enable, int width, int height) {
  return whole_frame_message(150, enable, width, height);
}

/// FramebufferUpdateRequest (3): U8 incremental, then the area.
inline std::vector<std::uint8_t> update_request_message(bool incremental, int width, int height) {
  return whole_frame_message(3, incremental, width, height);
}

}  // namespace rfbsim::test
