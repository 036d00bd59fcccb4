// SPDX-License-Identifier: GPL-2.0-or-later
// Broken map files: every mistake is a MapLoadError naming the YAML file, the key or image, and what was
// expected; nothing crashes.
#include <catch2/catch.hpp>

#include <cctype>

#include "map/map_server_loader.hpp"
#include "map_files.hpp"

using namespace rfbsim::sim;
using rfbsim::test::pgm_p5;
using rfbsim::test::ScratchDir;

namespace {

const std::string kGood =
    "image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\n";

// The message load_ros_map throws for a map YAML `text` (next to a valid room.pgm); fails if none.
std::string error_for(const std::string& text) {
  const ScratchDir dir;
  dir.write("room.pgm", pgm_p5(2, 2, 255, {0, 254, 254, 0}));
  const auto yaml = dir.write("lab.yaml", text);
  try {
    (void)load_ros_map(yaml);
  } catch (const MapLoadError& e) {
    const std::string message = e.what();
    // Every message starts with the YAML file's name.
    CHECK(message.rfind(yaml.string() + ":", 0) == 0);
    return message.substr(yaml.string().size());
  }
  FAIL("no MapLoadError for:\n" << text);
  return "";
}

// `text` with the line starting `key:` replaced by `line` (or removed if `line` is empty).
std::string with(const std::string& key, const std::string& line, std::string text = kGood) {
  const auto at = text.find(key + ":");
  const auto end = text.find('\n', at);
  text.replace(at, end - at + 1, line.empty() ? "" : line + "\n");
  return text;
}

}  // namespace

TEST_CASE("map_server_loader errors: the valid reference file loads") {
  const ScratchDir dir;
  dir.write("room.pgm", pgm_p5(2, 2, 255, {0, 254, 254, 0}));
  CHECK(load_ros_map(dir.write("lab.yaml", kGood)).values == std::vector<int>{0, 100, 100, 0});
}

TEST_CASE("map_server_loader errors: each missing required key is named") {
  CHECK(error_for(with("image", "")) == ": key 'image': missing (expected a picture file name)");
  CHECK(error_for(with("resolution", "")) == ": key 'resolution': missing (expected a positive number)");
  CHECK(error_for(with("origin", "")) == ": key 'origin': missing (expected a list of 3 numbers [x, y, yaw])");
  CHECK(error_for(with("negate", "")) == ": key 'negate': missing (expected 0, 1, true or false)");
  CHECK(error_for(with("occupied_thresh", "")) ==
        ": key 'occupied_thresh': missing (expected a number from 0 to 1)");
  CHECK(error_for(with("free_thresh", "")) == ": key 'free_thresh': missing (expected a number from 0 to 1)");
}

TEST_CASE("map_server_loader errors: values of the wrong type") {
  CHECK(error_for(with("resolution", "resolution: abc")) ==
        ": key 'resolution': expected a positive number, got 'abc'");
  CHECK(error_for(with("resolution", "resolution: [0.05]")) ==
        ": key 'resolution': expected a positive number, got a list of 1");
  CHECK(error_for(with("resolution", "resolution:")) == ": key 'resolution': expected a positive number, got nothing");
  CHECK(error_for(with("image", "image: {a: 1}")) == ": key 'image': expected a picture file name, got a mapping");
  CHECK(error_for(with("image", "image: ''")) == ": key 'image': expected a picture file name, got ''");
  CHECK(error_for(with("origin", "origin: [1, 2]")) ==
        ": key 'origin': expected a list of 3 numbers [x, y, yaw], got a list of 2");
  CHECK(error_for(with("origin", "origin: 0")) == ": key 'origin': expected a list of 3 numbers [x, y, yaw], got '0'");
  CHECK(error_for(with("origin", "origin: [1, north, 0]")) ==
        ": key 'origin[1]': expected a finite number, got 'north'");
  CHECK(error_for(with("negate", "negate: 2")) == ": key 'negate': expected 0, 1, true or false, got '2'");
  CHECK(error_for(kGood + "mode: Trinary\n") == ": key 'mode': expected trinary, scale or raw, got 'Trinary'");
  CHECK(error_for(with("free_thresh", "free_thresh: low")) ==
        ": key 'free_thresh': expected a number from 0 to 1, got 'low'");
}

TEST_CASE("map_server_loader errors: numbers out of range") {
  CHECK(error_for(with("resolution", "resolution: 0")) == ": key 'resolution': expected a positive number, got '0'");
  CHECK(error_for(with("resolution", "resolution: -0.05")) ==
        ": key 'resolution': expected a positive number, got '-0.05'");
  CHECK(error_for(with("resolution", "resolution: .nan")) ==
        ": key 'resolution': expected a positive number, got '.nan'");
  CHECK(error_for(with("resolution", "resolution: 1e999")) ==
        ": key 'resolution': expected a positive number, got '1e999'");
  CHECK(error_for(with("origin", "origin: [0, inf, 0]")) == ": key 'origin[1]': expected a finite number, got 'inf'");
  CHECK(error_for(with("occupied_thresh", "occupied_thresh: 1.5")) ==
        ": key 'occupied_thresh': expected a number from 0 to 1, got '1.5'");
  CHECK(error_for(with("free_thresh", "free_thresh: -0.1")) ==
        ": key 'free_thresh': expected a number from 0 to 1, got '-0.1'");
  CHECK(error_for(with("free_thresh", "free_thresh: 0.65")) ==
        ": key 'free_thresh': expected less than occupied_thresh (0.65), got '0.65'");
  // The edges of the range are fine: 0 and 1.
  CHECK_NOTHROW([] {
    const ScratchDir dir;
    dir.write("room.pgm", pgm_p5(1, 1, 255, {0}));
    (void)load_ros_map(dir.write("lab.yaml", with("free_thresh", "free_thresh: 0",
                                                   with("occupied_thresh", "occupied_thresh: 1"))));
  }());
}

TEST_CASE("map_server_loader errors: malformed YAML reports yaml-cpp's line and column") {
  const std::string message = error_for("image: room.pgm\nresolution: [0.05\nnegate: 0\n");
  // ":<line>:<column>: not valid YAML: <yaml-cpp's words>", counted from 1.
  const auto digits = [&](std::size_t from) {
    std::size_t end = from;
    while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end])) != 0) ++end;
    return end;
  };
  REQUIRE(message.size() > 1);
  CHECK(message[0] == ':');
  const std::size_t line_end = digits(1);
  CHECK(line_end > 1);
  CHECK(message[line_end] == ':');
  const std::size_t column_end = digits(line_end + 1);
  CHECK(column_end > line_end + 1);
  CHECK(message.substr(column_end).rfind(": not valid YAML: ", 0) == 0);
  CHECK(error_for("- just\n- a list\n").find(": expected a mapping with the keys image, resolution") == 0);
  CHECK(error_for("").find(": expected a mapping") == 0);
  const ScratchDir dir;
  CHECK_THROWS_WITH(load_ros_map(dir.path("none.yaml")),
                    dir.path("none.yaml").string() + ": cannot open: No such file or directory");
}

TEST_CASE("map_server_loader errors: pictures that are missing, truncated, garbage or absurd") {
  const ScratchDir dir;
  const auto try_image = [&](const std::string& image_name) {
    try {
      (void)load_ros_map(dir.yaml("lab.yaml", image_name));
    } catch (const MapLoadError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string prefix = dir.path("lab.yaml").string() + ": image ";

  CHECK(try_image("lab.pgm") == prefix + "'lab.pgm' (" + dir.path("lab.pgm").string() +
                                    "): cannot open: No such file or directory");

  dir.write("short.pgm", "P5\n4 4\n255\n\x01\x02\x03\x04\x05");
  CHECK(try_image("short.pgm") == prefix + "'short.pgm' (" + dir.path("short.pgm").string() +
                                      "): truncated: the header promises 4 x 4 pixels (16 bytes) but only 5 bytes follow");

  dir.write("short2.pgm", "P2\n2 2\n255\n0 0 0    ");
  CHECK(try_image("short2.pgm") == prefix + "'short2.pgm' (" + dir.path("short2.pgm").string() +
                                       "): truncated: the file ends before the pixel data");

  dir.write("junk.pgm", std::string("\x13\x37\xff\x00garbage", 11));
  CHECK(try_image("junk.pgm") ==
        prefix + "'junk.pgm' (" + dir.path("junk.pgm").string() + "): not a PGM (P2/P5) or PNG file");

  dir.write("zero.pgm", "P5\n0 0\n255\n");
  CHECK(try_image("zero.pgm") == prefix + "'zero.pgm' (" + dir.path("zero.pgm").string() + "): empty image: 0 x 0 pixels");

  dir.write("huge.pgm", "P5\n20000 20000\n255\n");
  CHECK(try_image("huge.pgm").find("): image too large: 20000 x 20000 pixels") != std::string::npos);

  std::filesystem::create_directories(dir.path("folder.pgm"));
  CHECK(try_image("folder.pgm") ==
        prefix + "'folder.pgm' (" + dir.path("folder.pgm").string() + "): cannot read: Is a directory");

  dir.write("cut.png", std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0", 18));
  CHECK(try_image("cut.png").find("(" + dir.path("cut.png").string() + "): bad PNG: ") != std::string::npos);
}

TEST_CASE("map_server_loader errors: deep or huge YAML is refused before yaml-cpp parses it") {
  // yaml-cpp recurses once per level; 100000 brackets would cost it deep recursion before its own guard.
  CHECK(error_for(std::string(100000, '[')) == ": YAML nested more than 32 levels deep (line 1)");
  std::string dashes;
  for (int i = 0; i < 40; ++i) dashes += "- ";
  CHECK(error_for(kGood + "extra:\n  " + dashes + "x\n") == ": YAML nested more than 32 levels deep (line 8)");
  CHECK(error_for(kGood + "# " + std::string(1'000'001, 'x') + "\n") ==
        ": too large for a map YAML file (over 1000000 bytes)");
}
