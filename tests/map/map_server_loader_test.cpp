// SPDX-License-Identifier: GPL-2.0-or-later
// map_server_loader: tiny hand-made maps give exactly the OccupancyGrid values map_server would give.
#include "map/map_server_loader.hpp"

#include <catch2/catch.hpp>

#include "map_files.hpp"

using namespace rfbsim::sim;
using rfbsim::test::pgm_p5;
using rfbsim::test::PngSpec;
using rfbsim::test::ScratchDir;

namespace {

// Loads a one-row map of the given 8-bit grey pixels, with the YAML's extra lines and thresholds.
LoadedMap load_row(const std::vector<int>& pixels, const std::string& extra, const std::string& occupied = "0.65",
                   const std::string& free = "0.196") {
  const ScratchDir dir;
  dir.write("row.pgm", pgm_p5(static_cast<int>(pixels.size()), 1, 255, pixels));
  return load_ros_map(dir.yaml("row.yaml", "row.pgm", extra, occupied, free));
}

std::vector<int> blocking(const LoadedMap& map) { return {map.grid.occupied.begin(), map.grid.occupied.end()}; }

}  // namespace

TEST_CASE("map_server_loader: trinary thresholds as map_server applies them") {
  // 0 black, 89 just occupied, 90 just not, 205 the usual unknown grey, 254 and 255 free.
  const LoadedMap map = load_row({0, 89, 90, 205, 254, 255}, "");
  CHECK(map.meta.mode == MapMode::Trinary);
  CHECK(map.values == std::vector<int>{100, 100, -1, -1, 0, 0});
  CHECK(blocking(map) == std::vector<int>{1, 1, 1, 1, 0, 0});
}

TEST_CASE("map_server_loader: a pixel exactly at a threshold is unknown (strict comparisons)") {
  // occupied_thresh 0.6 is hit exactly by v = 102, free_thresh 0.2 by v = 204.
  const LoadedMap map = load_row({101, 102, 103, 203, 204, 205}, "", "0.6", "0.2");
  CHECK(map.values == std::vector<int>{100, -1, -1, -1, -1, 0});
}

TEST_CASE("map_server_loader: negate makes white occupied") {
  // Without negate (and with a key map_server does not know, which is ignored) for comparison.
  const LoadedMap map = load_row({0, 255, 1, 166}, "negate_again: ignored\n");
  CHECK_FALSE(map.meta.negate);
  CHECK(map.values == std::vector<int>{100, 0, 100, -1});
  const ScratchDir dir;
  dir.write("n.pgm", pgm_p5(4, 1, 255, {0, 255, 1, 166}));
  dir.write("n.yaml", "image: n.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: true\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  const LoadedMap negated = load_ros_map(dir.path("n.yaml"));
  CHECK(negated.meta.negate);
  CHECK(negated.values == std::vector<int>{0, 100, 0, 100});
}

TEST_CASE("map_server_loader: scale mode grades the band between the thresholds") {
  // occ = (255 - v) / 255; in the band, rint(100 * (occ - 0.2) / 0.4).
  const LoadedMap map = load_row({0, 101, 102, 128, 153, 177, 178, 204, 205, 255}, "mode: scale\n", "0.6", "0.2");
  CHECK(map.meta.mode == MapMode::Scale);
  CHECK(map.values == std::vector<int>{100, 100, 100, 75, 50, 26, 25, 0, 0, 0});
  CHECK(blocking(map) == std::vector<int>{1, 1, 1, 0, 0, 0, 0, 0, 0, 0});
}

TEST_CASE("map_server_loader: raw mode passes the value on, negated if asked") {
  LoadedMap map = load_row({0, 50, 99, 100, 101, 254, 255}, "mode: raw\n");
  CHECK(map.values == std::vector<int>{0, 50, 99, 100, 101, 254, 255});
  CHECK(blocking(map) == std::vector<int>{0, 0, 0, 1, 1, 1, 1});
  const ScratchDir dir;
  dir.write("r.pgm", pgm_p5(3, 1, 255, {0, 155, 255}));
  dir.write("r.yaml", "image: r.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 1\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: raw\n");
  map = load_ros_map(dir.path("r.yaml"));
  CHECK(map.values == std::vector<int>{255, 100, 0});
}

TEST_CASE("map_server_loader: blocking rule per mode") {
  CHECK(value_blocks(100, MapMode::Trinary));
  CHECK(value_blocks(-1, MapMode::Trinary));
  CHECK_FALSE(value_blocks(0, MapMode::Trinary));
  CHECK(value_blocks(100, MapMode::Scale));
  CHECK(value_blocks(-1, MapMode::Scale));
  CHECK_FALSE(value_blocks(99, MapMode::Scale));
  CHECK_FALSE(value_blocks(1, MapMode::Scale));
  CHECK(value_blocks(100, MapMode::Raw));
  CHECK(value_blocks(255, MapMode::Raw));
  CHECK_FALSE(value_blocks(99, MapMode::Raw));
  CHECK_FALSE(value_blocks(0, MapMode::Raw));
}

TEST_CASE("map_server_loader: the picture's top row is the grid's last row") {
  const ScratchDir dir;
  // 3 x 2, one black pixel in the top-left corner.
  dir.write("flip.pgm", pgm_p5(3, 2, 255, {0, 254, 254, 254, 254, 254}));
  const LoadedMap map = load_ros_map(dir.yaml("flip.yaml", "flip.pgm"));
  REQUIRE(map.width == 3);
  REQUIRE(map.height == 2);
  CHECK(map.values == std::vector<int>{0, 0, 0, 100, 0, 0});
  CHECK(map.grid.is_occupied(0, 1));
  CHECK_FALSE(map.grid.is_occupied(0, 0));
  CHECK(map.grid.occupied.size() == 6);
}

TEST_CASE("map_server_loader: resolution and origin with yaw reach the grid") {
  const ScratchDir dir;
  dir.write("o.pgm", pgm_p5(4, 2, 255, {254, 254, 254, 254, 0, 254, 254, 254}));
  dir.write("o.yaml", "image: o.pgm\nresolution: 0.5\norigin: [1.5, -2.0, 1.5707963267948966]\nnegate: 0\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\nunknown_key: [1, 2]\n");
  const LoadedMap map = load_ros_map(dir.path("o.yaml"));
  CHECK(map.meta.image == dir.path("o.pgm"));
  CHECK(map.meta.resolution == 0.5);
  CHECK(map.meta.origin_x == 1.5);
  CHECK(map.meta.origin_y == -2.0);
  CHECK(map.meta.origin_yaw == 1.5707963267948966);
  CHECK(map.grid.resolution == 0.5);
  CHECK(map.grid.origin_x == 1.5);
  CHECK(map.grid.origin_y == -2.0);
  CHECK(map.grid.origin_yaw == 1.5707963267948966);
  // The grid is turned a quarter left about (1.5, -2): cell (0, 0)'s centre, (0.25, 0.25) in the map
  // frame, lies at (1.25, -1.75); the black pixel (bottom-left) is cell (0, 0).
  const Eigen::Vector2d centre = map.grid.cell_centre({0, 0});
  CHECK(centre.x() == Approx(1.25).margin(1e-12));
  CHECK(centre.y() == Approx(-1.75).margin(1e-12));
  CHECK(map.grid.is_occupied_at(1.25, -1.75));
  CHECK_FALSE(map.grid.is_occupied_at(1.25, -1.25));
}

TEST_CASE("map_server_loader: 16-bit samples keep their precision") {
  // 26214 / 65535 is exactly 102 / 255 (on the 0.6 threshold); 26213 is just darker, so occupied,
  // which an 8-bit reduction (both to 102) would miss. 32768 is mid grey: 127.50 in raw mode.
  const ScratchDir dir;
  dir.write("w.pgm", pgm_p5(4, 1, 65535, {26213, 26214, 32768, 65535}));
  LoadedMap map = load_ros_map(dir.yaml("w.yaml", "w.pgm", "", "0.6", "0.2"));
  CHECK(map.values == std::vector<int>{100, -1, -1, 0});
  map = load_ros_map(dir.yaml("raw.yaml", "w.pgm", "mode: raw\n", "0.6", "0.2"));
  CHECK(map.values == std::vector<int>{101, 102, 127, 255});

  PngSpec spec;
  spec.width = 2;
  spec.bit_depth = 16;
  spec.samples = {26213, 26214};
  rfbsim::test::write_png(dir.path("w.png"), spec);
  map = load_ros_map(dir.yaml("p.yaml", "w.png", "", "0.6", "0.2"));
  CHECK(map.values == std::vector<int>{100, -1});
}

TEST_CASE("map_server_loader: a plain PGM with a comment and an odd maxval") {
  const ScratchDir dir;
  // maxval 15: 7 is 119 on the 0..255 scale (occ 0.533, unknown).
  dir.write("p2.pgm", "P2\n# made by hand\n3 2\n15\n0 15 7\n15 15 0\n");
  const LoadedMap map = load_ros_map(dir.yaml("p2.yaml", "p2.pgm"));
  CHECK(map.values == std::vector<int>{0, 0, 100, 100, 0, -1});
}

TEST_CASE("map_server_loader: colour PNGs average R, G and B") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 3;
  spec.color_type = PNG_COLOR_TYPE_RGB;
  // Red averages to 85 (occ 0.667, occupied); cyan to 170 (occ 0.333, unknown); white is free.
  spec.samples = {255, 0, 0, 0, 255, 255, 255, 255, 255};
  rfbsim::test::write_png(dir.path("rgb.png"), spec);
  CHECK(load_ros_map(dir.yaml("rgb.yaml", "rgb.png")).values == std::vector<int>{100, -1, 0});
  // Raw: (10 + 20 + 31) / 3 = 20.33 -> 20.
  spec.width = 1;
  spec.samples = {10, 20, 31};
  rfbsim::test::write_png(dir.path("raw.png"), spec);
  CHECK(load_ros_map(dir.yaml("raw.yaml", "raw.png", "mode: raw\n")).values == std::vector<int>{20});
}

TEST_CASE("map_server_loader: alpha is averaged in for trinary, means unknown for scale, is ignored by raw") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 4;
  spec.color_type = PNG_COLOR_TYPE_GRAY_ALPHA;
  // (grey, alpha): black opaque, black see-through, white see-through, white almost opaque.
  spec.samples = {0, 255, 0, 0, 255, 0, 255, 254};
  rfbsim::test::write_png(dir.path("ga.png"), spec);
  // Trinary: (3 * grey + alpha) / 4 = 63.75 (occ 0.75), 0, 191.25 (occ 0.25), 254.75.
  CHECK(load_ros_map(dir.yaml("t.yaml", "ga.png")).values == std::vector<int>{100, 100, -1, 0});
  CHECK(load_ros_map(dir.yaml("s.yaml", "ga.png", "mode: scale\n")).values == std::vector<int>{100, -1, -1, -1});
  CHECK(load_ros_map(dir.yaml("r.yaml", "ga.png", "mode: raw\n")).values == std::vector<int>{0, 0, 255, 255});

  spec.color_type = PNG_COLOR_TYPE_RGBA;
  spec.width = 2;
  spec.samples = {0, 0, 0, 255, 255, 255, 255, 255};
  rfbsim::test::write_png(dir.path("rgba.png"), spec);
  CHECK(load_ros_map(dir.yaml("rgba.yaml", "rgba.png")).values == std::vector<int>{100, 0});
}

TEST_CASE("map_server_loader: palette PNGs use the palette's colours, and tRNS alpha") {
  const ScratchDir dir;
  PngSpec spec;
  spec.width = 3;
  spec.color_type = PNG_COLOR_TYPE_PALETTE;
  spec.samples = {1, 0, 2};
  spec.palette = {{255, 255, 255}, {0, 0, 0}, {205, 205, 205}};
  rfbsim::test::write_png(dir.path("pal.png"), spec);
  CHECK(load_ros_map(dir.yaml("pal.yaml", "pal.png")).values == std::vector<int>{100, 0, -1});
  spec.trns = {0, 255, 255};
  rfbsim::test::write_png(dir.path("trns.png"), spec);
  CHECK(load_ros_map(dir.yaml("trns.yaml", "trns.png", "mode: scale\n")).values == std::vector<int>{100, -1, 0});
}

TEST_CASE("map_server_loader: an absolute image path is used as it is") {
  const ScratchDir dir;
  const ScratchDir other;
  other.write("abs.pgm", pgm_p5(1, 1, 255, {0}));
  const LoadedMap map = load_ros_map(dir.yaml("abs.yaml", other.path("abs.pgm").string()));
  CHECK(map.meta.image == other.path("abs.pgm"));
  CHECK(map.values == std::vector<int>{100});
}
