// SPDX-License-Identifier: GPL-2.0-or-later
// XwdImage: a window's picture as `xwd -silent` writes it (X Window Dump, version 7), read into RGB for checks.
// Only what an X server at depth 24 writes is read: ZPixmap, 32 bits per pixel, TrueColor masks.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::test {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

struct XwdImage {
  int width = 0;
  int height = 0;
  std::vector<Rgb> pixels;  ///< row by row, top first
  [[nodiscard]] const Rgb& at(int x, int y) const { return pixels[static_cast<std::size_t>(y * width + x)]; }
};

/// Parses an XWD file's bytes; nullopt (with `error` saying why) for anything else, or a format this reader
/// does not handle.
std::optional<XwdImage> parse_xwd(const std::string& bytes, std::string& error);

/// The mean colour of the rows y0..y1-1 (all columns).
Rgb mean_of_rows(const XwdImage& image, int y0, int y1);

/// How many distinct colours the picture holds (a blank or single-colour window has one or two).
std::size_t distinct_colours(const XwdImage& image);

}  // namespace rfbsim::test
