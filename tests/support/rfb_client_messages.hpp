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

/// EnableContinuousUpdates (150): U8 enable, U16 x, y, w, h, for the whole width x height framebuffer.
inline std::vector<std::uint8_t> enable_continuous_message(bool enable, int width, int height) {
  std::vector<std::uint8_t> out{150, static_cast<std::uint8_t>(enable ? 1 : 0)};
  put_u16_clamped(out, 0);
  put_u16_clamped(out, 0);
  put_u16_clamped(out, width);
  put_u16_clamped(out, height);
  return out;
}

/// FramebufferUpdateRequest (3): U8 incremental, U16 x, y, w, h, for the whole width x height framebuffer.
inline std::vector<std::uint8_t> update_request_message(bool incremental, int width, int height) {
  std::vector<std::uint8_t> out{3, static_cast<std::uint8_t>(incremental ? 1 : 0)};
  put_u16_clamped(out, 0);
  put_u16_clamped(out, 0);
  put_u16_clamped(out, width);
  put_u16_clamped(out, height);
  return out;
}

}  // namespace rfbsim::test
