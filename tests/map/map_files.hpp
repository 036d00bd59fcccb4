// SPDX-License-Identifier: GPL-2.0-or-later
// Test helpers: a scratch folder per test and writers for hand-made PGM, PNG and map YAML files.
#pragma once

#include <png.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rfbsim::test {

/// A fresh folder under the system's temp directory, removed with everything in it at the end of the test.
class ScratchDir {
 public:
  ScratchDir() {
    static int counter = 0;
    dir_ = std::filesystem::temp_directory_path() /
           ("rfbsim_map_loader_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(dir_);
  }
  ~ScratchDir() { std::filesystem::remove_all(dir_); }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  [[nodiscard]] std::filesystem::path path(const std::string& name) const { return dir_ / name; }

  /// Writes `bytes` as they are to `name` and returns its path.
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    std::ofstream out(dir_ / name, std::ios::binary);
    out << bytes;
    return dir_ / name;
  }

  /// Writes a map YAML naming `image`, with the given thresholds and `extra` lines (e.g. "mode: raw\n").
  std::filesystem::path yaml(const std::string& name, const std::string& image, const std::string& extra = "",
                             const std::string& occupied = "0.65", const std::string& free = "0.196") const {
    return write(name, "image: " + image + "\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n" +
                           "occupied_thresh: " + occupied + "\nfree_thresh: " + free + "\n" + extra);
  }

 private:
  std::filesystem::path dir_;
};

/// A binary PGM (P5) with the given samples, top row first; 2 bytes per sample, big-endian, if maxval > 255.
inline std::string pgm_p5(int width, int height, int maxval, const std::vector<int>& samples,
                          const std::string& comment = "") {
  std::string bytes = "P5\n" + comment + std::to_string(width) + " " + std::to_string(height) + "\n" +
                      std::to_string(maxval) + "\n";
  for (const int s : samples) {
    if (maxval > 255) bytes += static_cast<char>((s >> 8) & 0xff);
    bytes += static_cast<char>(s & 0xff);
  }
  return bytes;
}

/// What write_png writes: samples top row first, `channels` per pixel for the colour type (1 per pixel,
/// the palette index, for a palette picture).
struct PngSpec {
  int width = 1;
  int height = 1;
  int color_type = PNG_COLOR_TYPE_GRAY;
  int bit_depth = 8;
  std::vector<int> samples;
  std::vector<png_color> palette;  ///< palette pictures only
  std::vector<png_byte> trns;      ///< palette alpha per entry (tRNS), palette pictures only
  bool interlaced = false;
  bool header_only = false;  ///< stop after IHDR, as a file claiming a size it does not hold
};

/// Writes a PNG with libpng, so the reader is tested against the reference encoder.
inline void write_png(const std::filesystem::path& file, const PngSpec& spec) {
  // Pack the samples first (sub-byte depths fill each byte from its top bit, 16 bits go big-endian), so
  // that nothing with a destructor is born after setjmp.
  const int per_pixel = spec.color_type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2
                        : spec.color_type == PNG_COLOR_TYPE_RGB      ? 3
                        : spec.color_type == PNG_COLOR_TYPE_RGBA     ? 4
                                                                     : 1;
  const std::size_t row_bytes = (static_cast<std::size_t>(spec.width * per_pixel * spec.bit_depth) + 7) / 8;
  std::vector<png_byte> rows(static_cast<std::size_t>(spec.height) * row_bytes);
  std::vector<png_bytep> row_pointers;
  for (int y = 0; y < spec.height && !spec.header_only; ++y) {
    png_bytep row = rows.data() + static_cast<std::size_t>(y) * row_bytes;
    row_pointers.push_back(row);
    for (int i = 0; i < spec.width * per_pixel; ++i) {
      const int s = spec.samples[static_cast<std::size_t>(y * spec.width * per_pixel + i)];
      if (spec.bit_depth == 16) {
        row[2 * i] = static_cast<png_byte>(s >> 8);
        row[2 * i + 1] = static_cast<png_byte>(s & 0xff);
      } else if (spec.bit_depth == 8) {
        row[i] = static_cast<png_byte>(s);
      } else {
        const int bit = i * spec.bit_depth;
        row[bit / 8] = static_cast<png_byte>(row[bit / 8] | (s << (8 - spec.bit_depth - bit % 8)));
      }
    }
  }

  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error("cannot write " + file.string());
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    throw std::runtime_error("libpng could not write the test picture");
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(spec.width), static_cast<png_uint_32>(spec.height),
               spec.bit_depth, spec.color_type, spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!spec.palette.empty()) {
    png_set_PLTE(png, info, spec.palette.data(), static_cast<int>(spec.palette.size()));
  }
  if (!spec.trns.empty()) {
    png_set_tRNS(png, info, spec.trns.data(), static_cast<int>(spec.trns.size()), nullptr);
  }
  png_write_info(png, info);
  if (!spec.header_only) {
    png_write_image(png, row_pointers.data());
    png_write_end(png, nullptr);
  }
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

}  // namespace rfbsim::test
