// SPDX-License-Identifier: GPL-2.0-or-later
// PGM (P2/P5) and PNG readers for map pictures: strict about the bytes, bounded in what they allocate.
#include "map/map_image.hpp"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "map/c_file.hpp"

namespace rfbsim::sim {
namespace {

using File = CFile;

// fopen rather than ifstream: errno after fopen is reliable, and libpng wants a FILE* anyway.
File open_file(const std::filesystem::path& file) {
  errno = 0;
  File f(std::fopen(file.c_str(), "rb"));
  if (!f) throw ImageError(std::string("cannot open: ") + std::strerror(errno));
  return f;
}

[[noreturn]] void read_failed(std::FILE* f) {
  if (std::ferror(f) != 0) throw ImageError(std::string("cannot read: ") + std::strerror(errno));
  throw ImageError("truncated: the file ends inside the pixel data");
}

// Bytes between the read position and the end of the file, so a header can be checked before allocating.
std::int64_t bytes_left(std::FILE* f) {
  const long here = std::ftell(f);
  if (here < 0 || std::fseek(f, 0, SEEK_END) != 0) read_failed(f);
  const long end = std::ftell(f);
  if (end < 0 || std::fseek(f, here, SEEK_SET) != 0) read_failed(f);
  return end - here;
}

// Checks the size a header announces against the caps, before anything of that size exists.
void check_size(std::int64_t width, std::int64_t height) {
  if (width <= 0 || height <= 0) {
    throw ImageError("empty image: " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
  }
  if (width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImagePixels) {
    throw ImageError("image too large: " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels (at most " + std::to_string(kMaxImageSide) + " per side and " +
                     std::to_string(kMaxImagePixels) + " in all)");
  }
}

// --- PGM ---------------------------------------------------------------------------------------------

// Netpbm allows whitespace and '#' comments (to the end of the line) between header fields.
void skip_space_and_comments(std::FILE* f) {
  for (int c = std::getc(f); c != EOF; c = std::getc(f)) {
    if (c == '#') {
      while (c != EOF && c != '\n' && c != '\r') c = std::getc(f);
    } else if (c != ' ' && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') {
      std::ungetc(c, f);
      return;
    }
  }
}

// A decimal number of the header or of a P2 raster; `what` names it in messages.
std::int64_t read_number(std::FILE* f, const char* what) {
  skip_space_and_comments(f);
  int c = std::getc(f);
  if (c == EOF) {
    if (std::ferror(f) != 0) read_failed(f);
    throw ImageError(std::string("truncated: the file ends before the ") + what);
  }
  if (c < '0' || c > '9') {
    throw ImageError(std::string("expected a number for the ") + what + ", got '" + static_cast<char>(c) + "'");
  }
  std::int64_t value = 0;
  for (; c >= '0' && c <= '9'; c = std::getc(f)) {
    value = value * 10 + (c - '0');
    if (value > 1'000'000'000) throw ImageError(std::string("the ") + what + " is absurdly large");
  }
  if (c != EOF) std::ungetc(c, f);
  return value;
}

MapImage read_pgm_from(std::FILE* f) {
  char magic[2] = {0, 0};
  if (std::fread(magic, 1, 2, f) != 2 || magic[0] != 'P' || (magic[1] != '5' && magic[1] != '2')) {
    throw ImageError("not a greyscale PGM (expected the magic number P5 or P2)");
  }
  const bool binary = magic[1] == '5';
  MapImage image;
  const std::int64_t width = read_number(f, "width");
  const std::int64_t height = read_number(f, "height");
  check_size(width, height);
  const std::int64_t maxval = read_number(f, "maxval");
  if (maxval < 1 || maxval > 65535) throw ImageError("maxval " + std::to_string(maxval) + " is not in 1..65535");
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.channels = 1;
  image.maxval = static_cast<int>(maxval);
  const std::int64_t pixels = width * height;
  const auto sample_fits = [&](std::int64_t value) {
    if (value > maxval) {
      throw ImageError("sample " + std::to_string(value) + " exceeds maxval " + std::to_string(maxval));
    }
  };

  if (binary) {
    // Exactly one whitespace byte ends the header; the raster starts right after it.
    const int c = std::getc(f);
    if (c == '#') {
      for (int d = c; d != EOF && d != '\n' && d != '\r';) d = std::getc(f);
    } else if (c != ' ' && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') {
      throw ImageError("expected whitespace after maxval");
    }
    const std::int64_t bytes_per_sample = maxval < 256 ? 1 : 2;
    const std::int64_t needed = pixels * bytes_per_sample;
    const std::int64_t have = bytes_left(f);
    if (have < needed) {
      throw ImageError("truncated: the header promises " + std::to_string(width) + " x " + std::to_string(height) +
                       " pixels (" + std::to_string(needed) + " bytes) but only " + std::to_string(have) +
                       " bytes follow");
    }
    image.samples.resize(static_cast<std::size_t>(pixels));
    std::vector<unsigned char> row(static_cast<std::size_t>(width * bytes_per_sample));
    for (std::int64_t y = 0; y < height; ++y) {
      if (std::fread(row.data(), 1, row.size(), f) != row.size()) read_failed(f);
      for (std::int64_t x = 0; x < width; ++x) {
        // 16-bit samples are big-endian (most significant byte first), as Netpbm specifies.
        const auto i = static_cast<std::size_t>(x * bytes_per_sample);
        const int value = bytes_per_sample == 1 ? row[i] : (row[i] << 8) | row[i + 1];
        sample_fits(value);
        image.samples[static_cast<std::size_t>(y * width + x)] = static_cast<std::uint16_t>(value);
      }
    }
    return image;
  }

  // Plain PGM: every sample takes at least one digit and one separator, so a short file is caught here.
  const std::int64_t have = bytes_left(f);
  if (have < 2 * pixels - 1) {
    throw ImageError("truncated: the header promises " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels but only " + std::to_string(have) + " bytes follow");
  }
  image.samples.resize(static_cast<std::size_t>(pixels));
  for (auto& sample : image.samples) {
    const std::int64_t value = read_number(f, "pixel data");
    sample_fits(value);
    sample = static_cast<std::uint16_t>(value);
  }
  return image;
}

// --- PNG ---------------------------------------------------------------------------------------------

// libpng reports errors through a callback that must not return; it longjmps back to decode_png.
struct PngContext {
  std::FILE* file = nullptr;
  char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* context = static_cast<PngContext*>(png_get_error_ptr(png));
  std::snprintf(context->message, sizeof context->message, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}  // warnings (bad gamma, odd chunks) do not change pixels

// The only function with setjmp: it holds no objects with destructors, so a longjmp skips nothing.
// Returns false with context.message set on any failure. Rows are appended as they decode, so a
// truncated file makes us allocate no more than what it really held (interlaced files need the whole
// picture at once, still within the caps).
bool decode_png(png_structp png, png_infop info, PngContext& context, MapImage& image,
                std::vector<unsigned char>& rows) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_init_io(png, context.file);
  png_set_sig_bytes(png, 8);
  png_set_user_limits(png, kMaxImageSide, kMaxImageSide);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  if (static_cast<std::int64_t>(width) * height > kMaxImagePixels) {
    std::snprintf(context.message, sizeof context.message, "image too large: %u x %u pixels", width, height);
    return false;
  }
  // Palettes become RGB, sub-byte grey becomes 8-bit and tRNS becomes a real alpha channel, so every
  // picture reaches us as 1..4 channels of 8 or 16 bits, as ImageMagick shows it to nav2.
  png_set_expand(png);
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.channels = png_get_channels(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  image.maxval = bit_depth == 16 ? 65535 : 255;
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  const std::size_t row_samples = static_cast<std::size_t>(width) * static_cast<std::size_t>(image.channels);
  if (row_bytes != row_samples * (bit_depth == 16 ? 2U : 1U)) {
    std::snprintf(context.message, sizeof context.message, "unsupported PNG layout");
    return false;
  }
  const auto convert_row = [&](const unsigned char* bytes, png_uint_32 y) {
    std::uint16_t* out = image.samples.data() + static_cast<std::size_t>(y) * row_samples;
    for (std::size_t i = 0; i < row_samples; ++i) {
      // PNG stores 16-bit samples big-endian.
      out[i] = bit_depth == 16 ? static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]) : bytes[i];
    }
  };
  if (passes == 1) {
    rows.resize(row_bytes);
    for (png_uint_32 y = 0; y < height; ++y) {
      png_read_row(png, rows.data(), nullptr);
      image.samples.resize(static_cast<std::size_t>(y + 1) * row_samples);
      convert_row(rows.data(), y);
    }
  } else {
    rows.resize(row_bytes * height);
    for (int pass = 0; pass < passes; ++pass) {
      for (png_uint_32 y = 0; y < height; ++y) png_read_row(png, rows.data() + y * row_bytes, nullptr);
    }
    image.samples.resize(static_cast<std::size_t>(height) * row_samples);
    for (png_uint_32 y = 0; y < height; ++y) convert_row(rows.data() + y * row_bytes, y);
  }
  return true;
}

MapImage read_png_from(std::FILE* f) {
  png_byte signature[8] = {};
  if (std::fread(signature, 1, 8, f) != 8 || png_sig_cmp(signature, 0, 8) != 0) {
    throw ImageError("not a PNG file (bad signature)");
  }
  PngContext context;
  context.file = f;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &context, on_png_error, on_png_warning);
  if (png == nullptr) throw ImageError("cannot start libpng");
  png_infop info = png_create_info_struct(png);
  // Frees libpng's state on every path out, exceptions included.
  struct Destroy {
    png_structp* png;
    png_infop* info;
    ~Destroy() { png_destroy_read_struct(png, info, nullptr); }
  } destroy{&png, &info};
  if (info == nullptr) throw ImageError("cannot start libpng");

  MapImage image;
  std::vector<unsigned char> rows;
  if (!decode_png(png, info, context, image, rows)) throw ImageError(std::string("bad PNG: ") + context.message);
  check_size(image.width, image.height);
  return image;
}

}  // namespace

MapImage read_pgm(const std::filesystem::path& file) {
  const File f = open_file(file);
  return read_pgm_from(f.get());
}

MapImage read_png(const std::filesystem::path& file) {
  const File f = open_file(file);
  return read_png_from(f.get());
}

MapImage read_map_image(const std::filesystem::path& file) {
  const File f = open_file(file);
  unsigned char head[8] = {};
  const std::size_t got = std::fread(head, 1, sizeof head, f.get());
  if (got == 0) {
    if (std::ferror(f.get()) != 0) read_failed(f.get());
    throw ImageError("empty file");
  }
  std::rewind(f.get());
  if (got >= 2 && head[0] == 'P' && (head[1] == '5' || head[1] == '2')) return read_pgm_from(f.get());
  if (got == 8 && png_sig_cmp(head, 0, 8) == 0) return read_png_from(f.get());
  if (got >= 2 && head[0] == 'P' && head[1] >= '1' && head[1] <= '7') {
    throw ImageError(std::string("unsupported Netpbm format P") + static_cast<char>(head[1]) +
                     " (expected a greyscale PGM, P5 or P2)");
  }
  throw ImageError("not a PGM (P2/P5) or PNG file");
}

}  // namespace rfbsim::sim
