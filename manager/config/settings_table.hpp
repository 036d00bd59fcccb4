// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's one table of settings. Each setting is declared once, with its name, the kind of value it takes
// (type and range), its help and how it is read and shown; everything else follows from the declaration:
//   - the YAML file's key (max_sessions; ros_connect is `connect:` under `ros:`), read by config.cpp;
//   - the command-line flag (--max-sessions, --ros-connect) and --help, declared on CLI11 by command_line.cpp;
//   - --print-config's YAML (print_config.cpp);
//   - the settings table of docs/deployment.md (settings_docs.cpp; a test compares the two).
#pragma once

#include <charconv>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace rfbsim::manager::config_table {

/// Applies a setting's values (one for a scalar, any number for a list); returns "" or what is wrong.
using Apply = std::function<std::string(ManagerConfig&, const std::vector<std::string>&)>;

/// A setting's value(s) in a config, as the file writes them; nullopt when it is unset (a default that is derived
/// from other settings, or none at all).
using Show = std::function<std::optional<std::vector<std::string>>(const ManagerConfig&)>;

/// What a setting takes: the shape of its value, its checks and its reading back.
struct ValueKind {
  std::string value_name;  ///< the value's name in --help: N, S, ADDR, FILE...
  std::string range;       ///< the values it takes, as --help and the docs say it ("1..10000"); "" = see the help
  bool list = false;       ///< a YAML sequence, or a comma-separated flag value
  Apply apply;
  Show show;
};

struct Setting {
  std::string key;           ///< "max_sessions"; "ros_connect" for `connect:` under the file's `ros:` section
  ValueKind kind;
  std::string help;          ///< what it does, in Markdown (`code`); --help leaves out the backticks
  std::string default_note;  ///< said of the default beside or instead of its value ("x11: `65536`")
  bool secret = false;       ///< never echoed in messages; --print-config writes <set>
};

/// The file's sections: a key "<section>_<name>" is written `name:` under `<section>:` in the file.
inline const std::vector<std::string> kSections = {"ros", "x11"};

/// What --print-config writes for a secret that is set; the file reader takes it back as "set elsewhere".
inline const std::string kSecretPlaceholder = "<set>";

/// Every setting, in the order --help, --print-config and the docs list them.
const std::vector<Setting>& settings();

/// The setting named `key`, or nullptr.
const Setting* find_setting(const std::string& key);

/// "--max-sessions" for "max_sessions".
std::string flag_of(const std::string& key);

/// The file's section a key belongs to ("ros" for ros_connect), or "" for a top-level key.
std::string section_of(const std::string& key);

/// How the file and the docs name a key: "max_sessions", or "ros.connect" for a section's.
std::string file_name_of(const std::string& key);

/// A help or note's Markdown as a terminal or a YAML comment shows it: without the backticks of `code`.
std::string plain_text(std::string markdown);

/// `text` as a whole integer within [low, high] into `out`; false (and `out` untouched) otherwise.
template <typename T>
bool parse_integer(const std::string& text, T low, T high, T& out) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < low || value > high) return false;
  out = value;
  return true;
}

/// A flag's list value, split at commas ("" is the empty list).
std::vector<std::string> split_commas(const std::string& text);

}  // namespace rfbsim::manager::config_table
