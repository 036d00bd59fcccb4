// SPDX-License-Identifier: GPL-2.0-or-later
// map_image: PGM and PNG pictures decode to the exact samples the files hold, whatever their layout.
#include "map/map_image.hpp"

#include <catch2/catch.hpp>

#include <sstream>

#include "map_files.hpp"

using namespace rfbsim::sim;
using rfbsim::test::PngSpec;
using rfbsim::test::ScratchDir;

namespace {

std::vector<int> samples_of(const MapImage& image) { return {image.samples.begin(), image.samples.end()}; }

}  // namespace

TEST_CASE("map_image: a binary PGM with a comment in its header") {
  const ScratchDir dir;
  const auto file = dir.write("a.pgm", rfbsim::test::pgm_p5(3, 2, 255, {0, 128, 255, 1, 2, 3},
                                                            "# CREATOR: GIMP PNM Filter Version 1.1\n"));
  const MapImage image = read_map_image(file);
  CHECK(image.width == 3);
  CHECK(image.height == 2);
  CHECK(image.channels == 1);
  CHECK(image.maxval == 255);
  CHECK(samples_of(image) == std::vector<int>{0, 128, 255, 1, 2, 3});
  CHECK(image.at(2, 1, 0) == 3);
}

TEST_CASE("map_image: a 16-bit binary PGM is big-endian") {
  const ScratchDir dir;
  const auto file = dir.write("a.pgm", rfbsim::test::pgm_p5(2, 1, 65535, {0x0102, 65535}));
  const MapImage image = read_pgm(file);
  CHECK(image.maxval == 65535);
  CHECK(samples_of(image) == std::vector<int>{258, 65535});
}

TEST_CASE("map_image: a plain PGM (P2) with comments between fields and an odd maxval") {
  const ScratchDir dir;
  const auto file = dir.write("a.pgm", "P2\n# by hand\n2 # width\n2\n15\n0 15\n# the second row\n7\t3\n");
  const MapImage image = read_map_image(file);
  CHECK(image.width == 2);
  CHECK(image.height == 2);
  CHECK(image.maxval == 15);
  CHECK(samples_of(image) == std::vector<int>{0, 15, 7, 3});
}

TEST_CASE("map_image: PGM samples above maxval, zero sizes and bad headers are refused") {
  const ScratchDir dir;
  CHECK_THROWS_WITH(read_pgm(dir.write("a.pgm", "P2\n2 1\n100\n5 101\n")), "sample 101 exceeds maxval 100");
  CHECK_THROWS_WITH(read_pgm(dir.write("b.pgm", "P5\n0 3\n255\n")), "empty image: 0 x 3 pixels");
  CHECK_THROWS_WITH(read_pgm(dir.write("c.pgm", "P5\n2 x\n255\n")), "expected a number for the height, got 'x'");
  CHECK_THROWS_WITH(read_pgm(dir.write("d.pgm", "P5\n2 2\n70000\n")), "maxval 70000 is not in 1..65535");
  CHECK_THROWS_WITH(read_pgm(dir.write("e.pgm", "P5\n2 2")), "truncated: the file ends before the maxval");
  CHECK_THROWS_WITH(read_map_image(dir.write("f.ppm", "P6\n1 1\n255\nabc")),
                    "unsupported Netpbm format P6 (expected a greyscale PGM, P5 or P2)");
}

TEST_CASE("map_image: a header larger than the caps is refused before anything is allocated") {
  const ScratchDir dir;
  CHECK_THROWS_WITH(read_pgm(dir.write("a.pgm", "P5\n20001 1\n255\n")),
                    "image too large: 20001 x 1 pixels (at most 20000 per side and 100000000 in all)");
  CHECK_THROWS_WITH(read_pgm(dir.write("b.pgm", "P5\n20000 20000\n255\n")),
                    "image too large: 20000 x 20000 pixels (at most 20000 per side and 100000000 in all)");
  CHECK_THROWS_WITH(read_pgm(dir.write("c.pgm", "P5\n99999999999 1\n255\n")), "the width is absurdly large");
  // Within the caps, but the bytes are not there: caught by comparing with the file's size.
  CHECK_THROWS_WITH(read_pgm(dir.write("d.pgm", "P5\n10000 10000\n255\nabc")),
                    "truncated: the header promises 10000 x 10000 pixels (100000000 bytes) but only 3 bytes follow");
  CHECK_THROWS_WITH(read_pgm(dir.write("e.pgm", "P2\n10000 10000\n255\n1 2 3")),
                    "truncated: the header promises 10000 x 10000 pixels but only 6 bytes follow");
}

TEST_CASE("map_image: PNG grey, grey + alpha, RGB and RGBA keep their channels") {
  const ScratchDir dir;
  struct Case {
    int color_type;
    int channels;
    std::vector<int> samples;
  };
  const std::vector<Case> cases = {
      {PNG_COLOR_TYPE_GRAY, 1, {0, 205}},
      {PNG_COLOR_TYPE_GRAY_ALPHA, 2, {0, 255, 205, 0}},
      {PNG_COLOR_TYPE_RGB, 3, {255, 0, 0, 1, 2, 3}},
      {PNG_COLOR_TYPE_RGBA, 4, {255, 0, 0, 255, 1, 2, 3, 4}},
  };
  for (const Case& c : cases) {
    PngSpec spec;
    spec.width = 2;
    spec.color_type = c.color_type;
    spec.samples = c.samples;
    rfbsim::test::write_png(dir.path("a.png"), spec);
    const MapImage image = read_map_image(dir.path("a.png"));
    CHECK(image.width == 2);
    CHECK(image.height == 1);
    CHECK(image.channels == c.channels);
    CHECK(image.maxval == 255);
    CHECK(samples_of(image) == c.samples);
  }
}

TEST_CASE("map_image: PNG palettes become colours, tRNS becomes alpha") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 3;
  spec.color_type = PNG_COLOR_TYPE_PALETTE;
  spec.samples = {1, 0, 2};
  spec.palette = {{255, 255, 255}, {0, 0, 0}, {10, 20, 30}};
  rfbsim::test::write_png(dir.path("a.png"), spec);
  MapImage image = read_png(dir.path("a.png"));
  CHECK(image.channels == 3);
  CHECK(samples_of(image) == std::vector<int>{0, 0, 0, 255, 255, 255, 10, 20, 30});

  spec.trns = {255, 255, 0};
  rfbsim::test::write_png(dir.path("b.png"), spec);
  image = read_png(dir.path("b.png"));
  CHECK(image.channels == 4);
  CHECK(samples_of(image) == std::vector<int>{0, 0, 0, 255, 255, 255, 255, 255, 10, 20, 30, 0});
}

TEST_CASE("map_image: 16-bit and 1-bit PNGs, and interlaced ones") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 2;
  spec.bit_depth = 16;
  spec.samples = {26213, 65535};
  rfbsim::test::write_png(dir.path("a.png"), spec);
  MapImage image = read_png(dir.path("a.png"));
  CHECK(image.maxval == 65535);
  CHECK(samples_of(image) == std::vector<int>{26213, 65535});

  // Sub-byte grey is widened to 8 bits: 1 becomes 255.
  spec.width = 9;
  spec.bit_depth = 1;
  spec.samples = {1, 0, 0, 1, 1, 0, 1, 0, 1};
  rfbsim::test::write_png(dir.path("b.png"), spec);
  image = read_png(dir.path("b.png"));
  CHECK(image.maxval == 255);
  CHECK(samples_of(image) == std::vector<int>{255, 0, 0, 255, 255, 0, 255, 0, 255});

  spec.width = 5;
  spec.height = 3;
  spec.bit_depth = 8;
  spec.interlaced = true;
  spec.samples = {0, 1, 2, 3, 4, 10, 11, 12, 13, 14, 20, 21, 22, 23, 24};
  rfbsim::test::write_png(dir.path("c.png"), spec);
  image = read_png(dir.path("c.png"));
  CHECK(image.width == 5);
  CHECK(image.height == 3);
  CHECK(samples_of(image) == spec.samples);
}

TEST_CASE("map_image: broken PNGs are refused with libpng's reason") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 64;
  spec.height = 64;
  spec.samples.assign(64 * 64, 0);
  for (std::size_t i = 0; i < spec.samples.size(); ++i) spec.samples[i] = static_cast<int>((i * 37) % 256);
  rfbsim::test::write_png(dir.path("a.png"), spec);
  std::ifstream in(dir.path("a.png"), std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string whole = bytes.str();
  // Cut inside the pixel data, then garble everything after the signature.
  const auto cut = dir.write("cut.png", whole.substr(0, whole.size() / 2));
  CHECK_THROWS_WITH(read_map_image(cut), Catch::Matchers::StartsWith("bad PNG: "));
  const auto garbled = dir.write("garbled.png", whole.substr(0, 8) + std::string(200, '\x5a'));
  CHECK_THROWS_WITH(read_map_image(garbled), Catch::Matchers::StartsWith("bad PNG: "));

  // An IHDR claiming 20000 x 20000 grey pixels (within libpng's limits, over ours), then the start of an
  // IDAT chunk, so that libpng reports the header and the cap is what stops the read.
  PngSpec huge;
  huge.width = 20000;
  huge.height = 20000;
  huge.header_only = true;
  rfbsim::test::write_png(dir.path("huge.png"), huge);
  std::ofstream(dir.path("huge.png"), std::ios::binary | std::ios::app) << std::string("\0\0\0\x08IDAT", 8);
  CHECK_THROWS_WITH(read_map_image(dir.path("huge.png")), "bad PNG: image too large: 20000 x 20000 pixels");
}

TEST_CASE("map_image: files that are not pictures") {
  const ScratchDir dir;
  CHECK_THROWS_WITH(read_map_image(dir.path("none.pgm")), "cannot open: No such file or directory");
  CHECK_THROWS_WITH(read_map_image(dir.write("empty.pgm", "")), "empty file");
  CHECK_THROWS_WITH(read_map_image(dir.write("junk.pgm", std::string("\x01\xfe\x7fjunk\x00\x13", 9))),
                    "not a PGM (P2/P5) or PNG file");
}
