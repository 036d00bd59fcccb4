// SPDX-License-Identifier: GPL-2.0-or-later
// MapImage: the pixels of a map picture (PGM or PNG) as the file holds them, before any ROS meaning is given
// to them, so that the format readers stay apart from map_server's occupancy rules.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace rfbsim::sim {

/// A picture that could not be read: the message says what is wrong with it (without the file name, which
/// the caller adds together with its own context).
class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Largest picture read, per side and in pixels: bounds the memory a hostile or broken file can make us
/// allocate (a 20000 x 5000 map at 0.05 m is already 1 km x 250 m).
inline constexpr int kMaxImageSide = 20000;
inline constexpr std::int64_t kMaxImagePixels = 100'000'000;

/// Decoded pixels, top row first (as in the file), each pixel `channels` samples in 0..maxval.
struct MapImage {
  int width = 0;     ///< pixels
  int height = 0;    ///< pixels
  int channels = 1;  ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA (palettes are expanded to RGB or RGBA)
  int maxval = 255;  ///< the largest sample value: 255 for 8-bit data, 65535 for 16-bit, or a PGM's maxval
  /// width * height * channels samples, row-major, row 0 at the top of the picture.
  std::vector<std::uint16_t> samples;

  [[nodiscard]] bool has_alpha() const { return channels == 2 || channels == 4; }
  /// Sample `channel` of pixel (x, y), y counted from the top.
  [[nodiscard]] std::uint16_t at(int x, int y, int channel) const {
    return samples[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                       static_cast<std::size_t>(channels) +
                   static_cast<std::size_t>(channel)];
  }
};

/// Reads a binary (P5) or plain (P2) PGM, any maxval 1..65535, comments allowed between header fields.
/// Throws ImageError for a malformed, truncated or oversized file; never allocates more than the header's
/// size allows, and checks that size against the file before allocating.
MapImage read_pgm(const std::filesystem::path& file);

/// Reads a PNG through libpng: grey, grey + alpha, RGB, RGBA or palette (expanded, tRNS becomes alpha),
/// 1..16 bits per sample (sub-byte grey is widened to 8 bits). Throws ImageError as read_pgm does.
MapImage read_png(const std::filesystem::path& file);

/// Reads a PGM or a PNG, told apart by the first bytes rather than the file name.
/// Throws ImageError, e.g. "cannot open: No such file or directory" or "not a PGM (P2/P5) or PNG file".
MapImage read_map_image(const std::filesystem::path& file);

}  // namespace rfbsim::sim
