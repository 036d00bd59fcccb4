// SPDX-License-Identifier: GPL-2.0-or-later
// YamlField: one node of a YAML document together with where it is (file, key path, line), so that every
// complaint about it can say "<file>:<line>: key 'crowd.speed.mean': expected a number, got 'fast'".
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rfbsim::sim {

class YamlField {
 public:
  /// The document's root; `file` names it in messages.
  YamlField(YAML::Node node, std::filesystem::path file);

  /// The child `key` of a mapping; throws when it is missing or this is not a mapping.
  [[nodiscard]] YamlField required(const std::string& key) const;
  /// The child `key`, or nothing when absent (or null).
  [[nodiscard]] std::optional<YamlField> optional(const std::string& key) const;
  /// Throws if this mapping has a key outside `known` (a misspelt key must not pass silently).
  void allow_only(const std::vector<std::string>& known) const;

  [[nodiscard]] double number(double low, double high) const;  ///< finite, within [low, high]
  [[nodiscard]] int integer(int low, int high) const;
  [[nodiscard]] std::uint64_t unsigned_integer() const;
  [[nodiscard]] std::string text() const;  ///< a non-empty scalar
  [[nodiscard]] bool boolean() const;
  /// The items of a sequence (of any length when max_items is 0).
  [[nodiscard]] std::vector<YamlField> sequence(std::size_t min_items = 0, std::size_t max_items = 0) const;
  /// The entries of a mapping, in file order.
  [[nodiscard]] std::vector<std::pair<std::string, YamlField>> mapping() const;
  [[nodiscard]] bool is_sequence() const { return node_.IsSequence(); }
  [[nodiscard]] bool is_scalar() const { return node_.IsScalar(); }
  [[nodiscard]] bool is_mapping() const { return node_.IsMap(); }

  /// "<file>:<line>: key '<path>': expected <expected>, got <what is there>".
  [[noreturn]] void fail(const std::string& expected) const;
  /// "<file>:<line>: key '<path>': <message>".
  [[noreturn]] void fail_with(const std::string& message) const;
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  YamlField(YAML::Node node, std::filesystem::path file, std::string path);
  [[nodiscard]] std::string where() const;
  [[nodiscard]] std::string shown() const;  // what the node holds, shortened, for messages

  YAML::Node node_;
  std::filesystem::path file_;
  std::string path_;  // "" for the root
};

/// Parses `file` into its root field. Throws ScenarioError for unreadable files and YAML syntax errors
/// (with yaml-cpp's line and column).
YamlField read_yaml_file(const std::filesystem::path& file);

}  // namespace rfbsim::sim
