// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's one table of settings: each key of the YAML file, which is also a flag (--max-sessions N is
// max_sessions: N), with how its values are checked and applied. config.cpp reads the file and the command
// line through it.
#pragma once

#include <charconv>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace rfbsim::manager::config_table {

/// Applies a setting's values (one for a scalar, any number for a list); returns "" or what is wrong.
using Apply = std::function<std::string(ManagerConfig&, const std::vector<std::string>&)>;

struct Setting {
  bool list = false;  ///< a YAML sequence, or a comma-separated flag value
  Apply apply;
};

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

/// Every setting by its key ("max_sessions", "ros.connect", ...).
const std::map<std::string, Setting>& settings();

/// The key a flag names: --max-sessions is max_sessions.
std::string flag_to_key(const std::string& flag);

/// A flag's list value, split at commas ("" is the empty list).
std::vector<std::string> split_commas(const std::string& text);

}  // namespace rfbsim::manager::config_table
