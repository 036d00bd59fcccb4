// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: map_server YAML files (the input is the map's YAML, next to a valid 40 x 40 room.pgm).
// Invariants: load_ros_map throws nothing but MapLoadError, naming the file; a loaded map has one value
// and one blocking flag per cell, values in their mode's range, and a positive resolution with thresholds
// in order; the YAML depth estimate is never below yaml-cpp's.
#include <cmath>
#include <string>

#include "fuzz_check.hpp"
#include "map/map_server_loader.hpp"
#include "scratch_files.hpp"
#include "yaml_depth_check.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::sim;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);
  rfbsim::fuzz::check_yaml_depth_estimate(text);
  const auto file = rfbsim::fuzz::ScratchFiles::get().write("map.yaml", text);
  LoadedMap map;
  try {
    map = load_ros_map(file);
  } catch (const MapLoadError& e) {
    check(std::string(e.what()).rfind(file.string(), 0) == 0, "error does not start with the file's name");
    return 0;
  }
  const auto cells = static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height);
  check(map.width > 0 && map.height > 0, "loaded map without cells");
  check(map.values.size() == cells && map.grid.occupied.size() == cells, "cell arrays of the wrong size");
  check(std::isfinite(map.meta.resolution) && map.meta.resolution > 0, "resolution not positive");
  check(map.meta.free_thresh < map.meta.occupied_thresh, "thresholds out of order");
  const int low = map.meta.mode == MapMode::Raw ? 0 : -1;
  const int high = map.meta.mode == MapMode::Raw ? 255 : 100;
  for (std::size_t i = 0; i < cells; ++i) {
    check(map.values[i] >= low && map.values[i] <= high, "cell value outside its mode's range");
    check((map.grid.occupied[i] != 0) == value_blocks(map.values[i], map.meta.mode), "blocking flag disagrees");
  }
  return 0;
}
