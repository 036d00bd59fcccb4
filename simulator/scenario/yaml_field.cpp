// SPDX-License-Identifier: GPL-2.0-or-later
// YamlField: typed, range-checked reads of YAML nodes with messages that say where.
#include "scenario/yaml_field.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "map/yaml_limits.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::sim {

YamlField::YamlField(YAML::Node node, std::filesystem::path file)
    : YamlField(std::move(node), std::move(file), "") {}

YamlField::YamlField(YAML::Node node, std::filesystem::path file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string YamlField::where() const {
  std::string text = file_.string();
  // yaml-cpp marks nodes that come from the file with their position; -1 for synthesized ones.
  if (node_.IsDefined() && node_.Mark().line >= 0) text += ":" + std::to_string(node_.Mark().line + 1);
  return text + ": " + (path_.empty() ? std::string("the document") : "key '" + path_ + "'");
}

std::string YamlField::shown() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsSequence()) return "a list";
  if (node_.IsMap()) return "a mapping";
  std::string value = node_.Scalar();
  if (value.size() > 40) value = value.substr(0, 37) + "...";
  return "'" + value + "'";
}

void YamlField::fail(const std::string& expected) const {
  throw ScenarioError(where() + ": expected " + expected + ", got " + shown());
}

void YamlField::fail_with(const std::string& message) const { throw ScenarioError(where() + ": " + message); }

YamlField YamlField::required(const std::string& key) const {
  const std::string child_path = path_.empty() ? key : path_ + "." + key;
  if (!node_.IsMap()) fail("a mapping with key '" + key + "'");
  const YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) {
    throw ScenarioError(where() + ": missing key '" + key + "'" + (path_.empty() ? "" : " (in '" + path_ + "')"));
  }
  return {child, file_, child_path};
}

std::optional<YamlField> YamlField::optional(const std::string& key) const {
  if (!node_.IsMap()) fail("a mapping");
  const YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) return std::nullopt;
  return YamlField(child, file_, path_.empty() ? key : path_ + "." + key);
}

void YamlField::allow_only(const std::vector<std::string>& known) const {
  if (!node_.IsMap()) fail("a mapping");
  for (const auto& entry : node_) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string("?");
    bool ok = false;
    for (const auto& k : known) ok = ok || k == key;
    if (ok) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    YamlField(entry.first, file_, path_.empty() ? key : path_ + "." + key)
        .fail_with("unknown key (known here: " + list + ")");
  }
}

double YamlField::number(double low, double high) const {
  if (!node_.IsScalar()) fail("a number");
  const std::string& s = node_.Scalar();
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  std::ostringstream range;
  range << "a number in [" << low << ", " << high << "]";
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) fail(range.str());
  if (value < low || value > high) fail(range.str());
  return value;
}

int YamlField::integer(int low, int high) const {
  const std::string expected = "an integer " + std::to_string(low) + ".." + std::to_string(high);
  if (!node_.IsScalar()) fail(expected);
  const std::string& s = node_.Scalar();
  int value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || value < low || value > high) fail(expected);
  return value;
}

std::uint64_t YamlField::unsigned_integer() const {
  if (!node_.IsScalar()) fail("a non-negative integer");
  const std::string& s = node_.Scalar();
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size()) fail("a non-negative integer");
  return value;
}

std::string YamlField::text() const {
  if (!node_.IsScalar() || node_.Scalar().empty()) fail("a text");
  return node_.Scalar();
}

bool YamlField::boolean() const {
  if (node_.IsScalar()) {
    const std::string& s = node_.Scalar();
    if (s == "true" || s == "1") return true;
    if (s == "false" || s == "0") return false;
  }
  fail("true or false");
}

std::vector<YamlField> YamlField::sequence(std::size_t min_items, std::size_t max_items) const {
  std::string expected = "a list";
  if (min_items > 0 && min_items == max_items) {
    expected = "a list of " + std::to_string(min_items);
  } else if (min_items > 0) {
    expected = "a list of at least " + std::to_string(min_items);
  }
  if (!node_.IsSequence()) fail(expected);
  if (node_.size() < min_items || (max_items > 0 && node_.size() > max_items)) fail(expected + " items");
  std::vector<YamlField> items;
  items.reserve(node_.size());
  for (std::size_t i = 0; i < node_.size(); ++i) {
    items.push_back(YamlField(node_[i], file_, path_ + "[" + std::to_string(i) + "]"));
  }
  return items;
}

std::vector<std::pair<std::string, YamlField>> YamlField::mapping() const {
  if (!node_.IsMap()) fail("a mapping");
  std::vector<std::pair<std::string, YamlField>> entries;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) YamlField(entry.first, file_, path_).fail("a plain key");
    const std::string key = entry.first.Scalar();
    entries.emplace_back(key, YamlField(entry.second, file_, path_.empty() ? key : path_ + "." + key));
  }
  return entries;
}

YamlField read_yaml_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ScenarioError(file.string() + ": cannot open the file");
  // Read in blocks and stop past the limit, so that a huge file (or /dev/zero) is refused without being held.
  std::string text;
  char block[4096];
  while (in.read(block, sizeof block) || in.gcount() > 0) {
    text.append(block, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxYamlBytes) break;
  }
  if (in.bad()) throw ScenarioError(file.string() + ": cannot read the file");
  // yaml-cpp recurses once per level of nesting: refuse deep text before it does.
  if (const std::string problem = yaml_limits_problem(text); !problem.empty()) {
    throw ScenarioError(file.string() + ": " + problem);
  }
  try {
    return YamlField(YAML::Load(text), file);
  } catch (const YAML::Exception& e) {
    throw ScenarioError(file.string() + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                        ": not valid YAML: " + e.msg);
  }
}

}  // namespace rfbsim::sim
