// SPDX-License-Identifier: GPL-2.0-or-later
// map_server YAML + picture -> OccupancyGrid values and a blocking GridMap (the rules are in the header).
#include "map/map_server_loader.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

#include "map/c_file.hpp"
#include "map/yaml_limits.hpp"

namespace rfbsim::sim {
namespace {

// --- The YAML file -----------------------------------------------------------------------------------

// One YAML file being read; every error it raises starts with the file's name.
class YamlDoc {
 public:
  YamlDoc(const std::filesystem::path& file, YAML::Node root) : file_(file.string()), root_(std::move(root)) {}

  [[noreturn]] void fail(const std::string& problem) const { throw MapLoadError(file_ + ": " + problem); }

  // The node under `key`; a missing key is reported with what should have been there.
  [[nodiscard]] YAML::Node required(const char* key, const std::string& expected) const {
    YAML::Node node = root_[key];
    if (!node.IsDefined()) fail(std::string("key '") + key + "': missing (expected " + expected + ")");
    return node;
  }
  [[nodiscard]] YAML::Node optional(const char* key) const { return root_[key]; }

  [[noreturn]] void bad_value(const std::string& key, const std::string& expected, const YAML::Node& node) const {
    fail("key '" + key + "': expected " + expected + ", got " + shown(node));
  }

  // A finite number; YAML's quoted or plain scalars both count, as yaml-cpp's as<double> allows.
  [[nodiscard]] double number(const YAML::Node& node, const std::string& key, const std::string& expected) const {
    if (!node.IsScalar()) bad_value(key, expected, node);
    std::string_view text = node.Scalar();
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);  // from_chars takes no '+'
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
      bad_value(key, expected, node);
    }
    return value;
  }

 private:
  static std::string shown(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + node.Scalar() + "'";
    if (node.IsSequence()) return "a list of " + std::to_string(node.size());
    if (node.IsMap()) return "a mapping";
    return "nothing";
  }

  std::string file_;
  YAML::Node root_;
};

// Reads the whole YAML file; yaml-cpp's own LoadFile would not say why a file cannot be opened.
YAML::Node parse_yaml_file(const std::filesystem::path& file) {
  const std::string name = file.string();
  errno = 0;
  const CFile f(std::fopen(file.c_str(), "rb"));
  if (!f) throw MapLoadError(name + ": cannot open: " + std::strerror(errno));
  std::string text;
  char buffer[4096];
  for (std::size_t got = 0; (got = std::fread(buffer, 1, sizeof buffer, f.get())) > 0;) {
    text.append(buffer, got);
    // A map's YAML is a few lines; anything this large is not one, and we will not hold it.
    if (text.size() > kMaxYamlBytes) {
      throw MapLoadError(name + ": too large for a map YAML file (over " + std::to_string(kMaxYamlBytes) + " bytes)");
    }
  }
  if (std::ferror(f.get()) != 0) throw MapLoadError(name + ": cannot read: " + std::strerror(errno));
  // yaml-cpp recurses once per level of nesting: refuse deep text before it does.
  if (const std::string problem = yaml_limits_problem(text); !problem.empty()) {
    throw MapLoadError(name + ": " + problem);
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    // yaml-cpp counts lines and columns from 0; editors count from 1.
    throw MapLoadError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                       ": not valid YAML: " + e.msg);
  }
}

MapMetadata parse_metadata(const YamlDoc& doc, const std::filesystem::path& yaml_file, std::string& image_name) {
  MapMetadata meta;

  // image: relative to the YAML file's folder unless absolute, as map_server does.
  const char* const image_expected = "a picture file name";
  const YAML::Node image = doc.required("image", image_expected);
  if (!image.IsScalar() || image.Scalar().empty()) doc.bad_value("image", image_expected, image);
  image_name = image.Scalar();
  const std::filesystem::path image_path(image_name);
  meta.image = image_path.is_absolute() ? image_path : yaml_file.parent_path() / image_path;

  const char* const resolution_expected = "a positive number";
  const YAML::Node resolution = doc.required("resolution", resolution_expected);
  meta.resolution = doc.number(resolution, "resolution", resolution_expected);
  if (!(meta.resolution > 0.0)) doc.bad_value("resolution", resolution_expected, resolution);

  const char* const origin_expected = "a list of 3 numbers [x, y, yaw]";
  const YAML::Node origin = doc.required("origin", origin_expected);
  if (!origin.IsSequence() || origin.size() != 3) doc.bad_value("origin", origin_expected, origin);
  double* const pose[3] = {&meta.origin_x, &meta.origin_y, &meta.origin_yaw};
  for (std::size_t i = 0; i < 3; ++i) {
    *pose[i] = doc.number(origin[i], "origin[" + std::to_string(i) + "]", "a finite number");
  }

  // negate: ROS 1 reads an integer, ROS 2 an integer or a bool; we take 0, 1 or a YAML bool.
  const char* const negate_expected = "0, 1, true or false";
  const YAML::Node negate = doc.required("negate", negate_expected);
  if (!negate.IsScalar()) doc.bad_value("negate", negate_expected, negate);
  if (negate.Scalar() == "0" || negate.Scalar() == "1") {
    meta.negate = negate.Scalar() == "1";
  } else {
    try {
      meta.negate = negate.as<bool>();
    } catch (const YAML::Exception&) {
      doc.bad_value("negate", negate_expected, negate);
    }
  }

  const char* const thresh_expected = "a number from 0 to 1";
  const YAML::Node occupied = doc.required("occupied_thresh", thresh_expected);
  meta.occupied_thresh = doc.number(occupied, "occupied_thresh", thresh_expected);
  if (meta.occupied_thresh < 0.0 || meta.occupied_thresh > 1.0) {
    doc.bad_value("occupied_thresh", thresh_expected, occupied);
  }
  const YAML::Node free = doc.required("free_thresh", thresh_expected);
  meta.free_thresh = doc.number(free, "free_thresh", thresh_expected);
  if (meta.free_thresh < 0.0 || meta.free_thresh > 1.0) doc.bad_value("free_thresh", thresh_expected, free);
  if (!(meta.free_thresh < meta.occupied_thresh)) {
    doc.fail("key 'free_thresh': expected less than occupied_thresh (" + occupied.Scalar() + "), got '" +
             free.Scalar() + "'");
  }

  // mode: map_server's three names, exactly as it spells them.
  const YAML::Node mode = doc.optional("mode");
  if (mode.IsDefined()) {
    const char* const mode_expected = "trinary, scale or raw";
    if (!mode.IsScalar()) doc.bad_value("mode", mode_expected, mode);
    if (mode.Scalar() == "trinary") {
      meta.mode = MapMode::Trinary;
    } else if (mode.Scalar() == "scale") {
      meta.mode = MapMode::Scale;
    } else if (mode.Scalar() == "raw") {
      meta.mode = MapMode::Raw;
    } else {
      doc.bad_value("mode", mode_expected, mode);
    }
  }
  return meta;
}

// --- Pixels to values --------------------------------------------------------------------------------

// One pixel's value under map_server's rules (image row y counted from the top).
int pixel_value(const MapImage& image, int x, int y, const MapMetadata& meta) {
  const bool colour = image.channels >= 3;
  const int alpha_channel = image.has_alpha() ? image.channels - 1 : -1;
  // Grey stands for three equal colour channels, which is how both ROS loaders see it when alpha is
  // averaged in (ROS 1's SDL widens grey + alpha to RGBA; ROS 2 reads R, G and B from ImageMagick).
  const auto sample = [&](int channel) { return static_cast<double>(image.at(x, y, channel)); };
  const double colour_sum = colour ? sample(0) + sample(1) + sample(2) : 3.0 * sample(0);
  const double maxval = image.maxval;
  const double alpha = alpha_channel >= 0 ? sample(alpha_channel) : maxval;
  const bool average_alpha = meta.mode == MapMode::Trinary && alpha_channel >= 0;
  const double sum = average_alpha ? colour_sum + alpha : colour_sum;
  const double count = average_alpha ? 4.0 : 3.0;
  // For 8-bit pictures this is exactly ROS 1's color_sum / n_channels (the 255s cancel exactly).
  double v = (sum * 255.0) / (count * maxval);
  if (meta.negate) v = 255.0 - v;

  if (meta.mode == MapMode::Raw) return static_cast<int>(std::floor(v));
  if (meta.mode == MapMode::Scale && alpha < maxval) return -1;
  const double occ = (255.0 - v) / 255.0;
  if (occ > meta.occupied_thresh) return 100;
  if (occ < meta.free_thresh) return 0;
  if (meta.mode == MapMode::Trinary) return -1;
  return static_cast<int>(std::nearbyint((occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh) * 100.0));
}

}  // namespace

bool value_blocks(int value, MapMode mode) {
  if (mode == MapMode::Raw) return value >= 100;
  return value == 100 || value == -1;
}

LoadedMap map_from_image(const MapImage& image, const MapMetadata& meta) {
  LoadedMap map;
  map.meta = meta;
  map.width = image.width;
  map.height = image.height;
  const auto cells = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  map.values.resize(cells);
  map.grid.width = image.width;
  map.grid.height = image.height;
  map.grid.resolution = meta.resolution;
  map.grid.origin_x = meta.origin_x;
  map.grid.origin_y = meta.origin_y;
  map.grid.origin_yaw = meta.origin_yaw;
  map.grid.occupied.resize(cells);
  // The picture's top row is the grid's last: image row y is grid row height - 1 - y.
  for (int y = 0; y < image.height; ++y) {
    const auto row = static_cast<std::size_t>(image.height - 1 - y);
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = row * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x);
      map.values[i] = pixel_value(image, x, y, meta);
      map.grid.occupied[i] = value_blocks(map.values[i], meta.mode) ? 1 : 0;
    }
  }
  return map;
}

LoadedMap load_ros_map(const std::filesystem::path& yaml_file) {
  YAML::Node root = parse_yaml_file(yaml_file);
  const YamlDoc doc(yaml_file, root);
  if (!root.IsMap()) {
    doc.fail("expected a mapping with the keys image, resolution, origin, negate, occupied_thresh and free_thresh");
  }
  std::string image_name;
  const MapMetadata meta = parse_metadata(doc, yaml_file, image_name);
  MapImage image;
  try {
    image = read_map_image(meta.image);
  } catch (const ImageError& e) {
    doc.fail("image '" + image_name + "' (" + meta.image.string() + "): " + e.what());
  }
  return map_from_image(image, meta);
}

}  // namespace rfbsim::sim
