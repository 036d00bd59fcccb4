// SPDX-License-Identifier: GPL-2.0-or-later
// Loader for ROS map_server maps (a YAML file naming a PGM or PNG picture), with map_server's own pixel
// rules, so a map drawn for a ROS robot means the same walls here.
//
// Per pixel (image row j, top = 0, becomes grid row H-1-j: the picture's top is +y):
//   - v = average of the channels, on the 0..255 scale (a 16-bit or other-maxval sample s counts as
//     s * 255 / maxval, as ImageMagick does for nav2). Grey counts as R = G = B = grey. Alpha is averaged in
//     with the colours in Trinary mode only (both ROS versions keep this quirk); Scale and Raw average the
//     colours alone.
//   - negate: v = 255 - v.   occ = (255 - v) / 255.
//   - Trinary: occ > occupied_thresh -> 100; occ < free_thresh -> 0; otherwise -1 (unknown).
//   - Scale: alpha < maxval -> -1; occ > occupied_thresh -> 100; occ < free_thresh -> 0; otherwise
//     rint(100 * (occ - free_thresh) / (occupied_thresh - free_thresh)) (rounding half to even).
//   - Raw: the value itself, floor(v) in 0..255, negate applied; no thresholds.
//
// Where ROS 1 (map_server, noetic) and ROS 2 (nav2_map_server) differ, we follow:
//   - Palette PNGs: ROS 2 (the palette colours; ROS 1's SDL path averaged the palette index). 16-bit
//     samples: ROS 2 (full precision; ROS 1 stripped them to 8 bits).
//   - Scale: ROS 2 (any alpha below opaque is unknown, checked first, and the in-between value is
//     rint(100 * ratio); ROS 1 made only alpha == 0 unknown, after the thresholds, and used trunc(99 * ratio)).
//   - Raw: ROS 1 (negate applies and every 0..255 value is passed on; ROS 2 ignores negate and turns values
//     above 100 into -1), so the picture's byte survives for the caller to interpret.
//   - occ is computed as ROS 1 does, (255 - v) / 255, not ROS 2's 1 - v / 255 (the two can differ by one
//     rounding step exactly at a threshold).
//   - The YAML: `negate` may be 0, 1, true or false (ROS 2 accepts both); `mode` is optional (both).
//     Unlike either ROS loader we validate every value (see load_ros_map).
#pragma once

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "map/grid_map.hpp"
#include "map/map_image.hpp"

namespace rfbsim::sim {

/// How pixel shades become occupancy values (map_server's `mode` key).
enum class MapMode { Trinary, Scale, Raw };

/// The contents of a map_server YAML file.
struct MapMetadata {
  /// The picture, already resolved: relative names in the YAML are taken from the YAML file's folder.
  std::filesystem::path image;
  double resolution = 0.05;  ///< m per pixel (cell), > 0
  double origin_x = 0.0;     ///< m, world position of the lower-left corner of the lower-left pixel
  double origin_y = 0.0;     ///< m
  double origin_yaw = 0.0;   ///< rad, counter-clockwise turn of the grid about that corner
  bool negate = false;       ///< true: white is occupied and black is free
  double occupied_thresh = 0.65;  ///< occupancy fraction 0..1 above which a pixel is occupied
  double free_thresh = 0.196;     ///< occupancy fraction 0..1 below which a pixel is free; < occupied_thresh
  MapMode mode = MapMode::Trinary;
};

/// A loaded map: the ROS OccupancyGrid values and the blocking grid the simulator walks on.
struct LoadedMap {
  MapMetadata meta;
  int width = 0;   ///< cells (= picture width)
  int height = 0;  ///< cells (= picture height)
  /// width * height values, row-major, row 0 at the bottom (the picture's last row). Trinary and Scale:
  /// the ROS OccupancyGrid value, 0..100 or -1 for unknown. Raw: the pixel's value 0..255.
  std::vector<int> values;
  /// The same cells as blocking (1) or free (0), by value_blocks; resolution and origin from `meta`.
  GridMap grid;
};

/// Whether a cell with occupancy value `value` (as in LoadedMap::values) blocks walkers and the robot.
/// We block what a ROS costmap_2d static layer (lethal_threshold 100, unknown 255) marks lethal or unknown,
/// since a simulated world has no way to explore unknown space:
///   - Trinary and Scale: value == 100 (occupied) or value == -1 (unknown). Scale's in-between values
///     1..99 are graded costs, not walls; they do not block.
///   - Raw: value >= 100, i.e. 100 (occupied), 101..254 (which costmap_2d also reads as lethal) and 255
///     (the byte of ROS's -1, unknown).
[[nodiscard]] bool value_blocks(int value, MapMode mode);

/// A map file that cannot be used. The message always names the YAML file, then the key or the image and
/// what was expected, e.g. "maps/lab.yaml: key 'resolution': expected a positive number, got 'abc'".
class MapLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Loads a map_server YAML file and its picture.
/// Required keys: image, resolution, origin ([x, y, yaw], finite numbers), negate, occupied_thresh,
/// free_thresh; optional: mode (trinary | scale | raw, default trinary); other keys are ignored.
/// Checked: resolution finite and > 0; thresholds finite, in [0, 1], free_thresh < occupied_thresh.
/// The picture: PGM (P5 or P2) or PNG, at most kMaxImageSide per side and kMaxImagePixels in all.
/// Throws MapLoadError on any problem: unreadable or malformed YAML (with yaml-cpp's line and column),
/// a missing or bad key, or a missing, truncated, oversized or undecodable picture.
LoadedMap load_ros_map(const std::filesystem::path& yaml_file);

/// Applies map_server's pixel rules (see the top of this file) to a decoded picture; `meta.image` is only
/// recorded. The caller has checked `meta` as load_ros_map does.
LoadedMap map_from_image(const MapImage& image, const MapMetadata& meta);

}  // namespace rfbsim::sim
