// SPDX-License-Identifier: GPL-2.0-or-later
// XwdImage: reading an X Window Dump (the header's 25 big-endian 32-bit fields, the window name, the colour
// map, then the pixels).
#include "xwd_image.hpp"

#include <bit>
#include <unordered_set>

namespace rfbsim::test {

namespace {

// The header's fields, by index (XWDFileHeader in X11/XWDFile.h).
enum Field {
  kHeaderSize = 0,
  kFileVersion = 1,
  kPixmapFormat = 2,
  kWidth = 4,
  kHeight = 5,
  kByteOrder = 7,
  kBitsPerPixel = 11,
  kBytesPerLine = 12,
  kRedMask = 14,
  kGreenMask = 15,
  kBlueMask = 16,
  kColourCount = 19,
  kFieldCount = 25,
};
constexpr std::uint32_t kZPixmap = 2;
constexpr std::size_t kColourEntryBytes = 12;

std::uint32_t big_endian_u32(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) value = (value << 8) | static_cast<std::uint8_t>(bytes[at + i]);
  return value;
}

std::uint32_t pixel_u32(const std::string& bytes, std::size_t at, bool lsb_first) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto byte = static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[at + i]));
    value |= lsb_first ? byte << (8 * i) : byte << (8 * (3 - i));
  }
  return value;
}

// The 8-bit channel that `mask` selects in `pixel`.
std::uint8_t channel(std::uint32_t pixel, std::uint32_t mask) {
  if (mask == 0) return 0;
  return static_cast<std::uint8_t>((pixel & mask) >> std::countr_zero(mask));
}

}  // namespace

std::optional<XwdImage> parse_xwd(const std::string& bytes, std::string& error) {
  if (bytes.size() < kFieldCount * 4) {
    error = "shorter than an XWD header (" + std::to_string(bytes.size()) + " bytes)";
    return std::nullopt;
  }
  std::uint32_t h[kFieldCount];
  for (std::size_t i = 0; i < kFieldCount; ++i) h[i] = big_endian_u32(bytes, i * 4);
  if (h[kFileVersion] != 7 || h[kPixmapFormat] != kZPixmap || h[kBitsPerPixel] != 32) {
    error = "not a 32-bit ZPixmap XWD version 7 (version " + std::to_string(h[kFileVersion]) + ", format " +
            std::to_string(h[kPixmapFormat]) + ", " + std::to_string(h[kBitsPerPixel]) + " bits per pixel)";
    return std::nullopt;
  }
  const std::size_t width = h[kWidth];
  const std::size_t height = h[kHeight];
  const std::size_t line = h[kBytesPerLine];
  const std::size_t start = std::size_t{h[kHeaderSize]} + std::size_t{h[kColourCount]} * kColourEntryBytes;
  if (width == 0 || height == 0 || width > 16384 || height > 16384 || line < width * 4 ||
      start + line * height > bytes.size()) {
    error = "XWD of " + std::to_string(width) + "x" + std::to_string(height) + " does not fit its " +
            std::to_string(bytes.size()) + " bytes";
    return std::nullopt;
  }
  XwdImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.pixels.reserve(width * height);
  const bool lsb_first = h[kByteOrder] == 0;
  for (std::size_t y = 0; y < height; ++y) {
    for (std::size_t x = 0; x < width; ++x) {
      const std::uint32_t p = pixel_u32(bytes, start + y * line + x * 4, lsb_first);
      image.pixels.push_back({channel(p, h[kRedMask]), channel(p, h[kGreenMask]), channel(p, h[kBlueMask])});
    }
  }
  return image;
}

Rgb mean_of_rows(const XwdImage& image, int y0, int y1) {
  double r = 0, g = 0, b = 0;
  double n = 0;
  for (int y = y0; y < y1 && y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgb& p = image.at(x, y);
      r += p.r;
      g += p.g;
      b += p.b;
      n += 1;
    }
  }
  if (n == 0) return {};
  return {static_cast<std::uint8_t>(r / n), static_cast<std::uint8_t>(g / n), static_cast<std::uint8_t>(b / n)};
}

std::size_t distinct_colours(const XwdImage& image) {
  std::unordered_set<std::uint32_t> seen;
  for (const Rgb& p : image.pixels) seen.insert((std::uint32_t{p.r} << 16) | (std::uint32_t{p.g} << 8) | p.b);
  return seen.size();
}

}  // namespace rfbsim::test
