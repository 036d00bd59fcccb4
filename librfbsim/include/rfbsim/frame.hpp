// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::FrameView: a borrowed, read-only picture handed from a renderer to the server.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rfbsim {

/// A read-only view of one frame: RGBA8 pixels (bytes R, G, B, A), top row first.
/// The view does not own the pixels; they must stay valid for the duration of the call it is passed to.
struct FrameView {
  const std::uint8_t* pixels = nullptr;  ///< first byte of the top row; never null in a valid view
  int width = 0;                          ///< pixels per row
  int height = 0;                         ///< rows
  std::size_t stride = 0;                 ///< bytes from one row to the next; 0 means width * 4

  /// Bytes between rows, resolving the 0 default.
  [[nodiscard]] std::size_t row_bytes() const {
    return stride != 0 ? stride : static_cast<std::size_t>(width) * 4U;
  }
  /// First byte of row y (0 = top).
  [[nodiscard]] const std::uint8_t* row(int y) const {
    return pixels + static_cast<std::size_t>(y) * row_bytes();
  }
};

}  // namespace rfbsim
