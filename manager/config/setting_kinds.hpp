// SPDX-License-Identifier: GPL-2.0-or-later
// The kinds of value sim_manager's settings take (settings_table.hpp): each one knows its checks, its range as
// --help says it, and how to read its field back for --print-config, so that a range is written once.
#pragma once

#include <chrono>
#include <functional>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "cli/command_line.hpp"
#include "config/settings_table.hpp"

namespace rfbsim::manager::config_table {

/// A whole number in [low, high].
ValueKind integer(int ManagerConfig::*field, int low, int high);

/// Whole seconds in [low, a week].
ValueKind seconds(std::chrono::seconds ManagerConfig::*field, long long low);

/// An abuse limit: a count 0..1000000, 0 = off.
ValueKind abuse_count(int AbuseLimits::*field);

/// An abuse limit in whole seconds 0..3600, 0 = off.
ValueKind abuse_seconds(std::chrono::seconds AbuseLimits::*field);

/// Any text of at least `min_length` characters (a path, a program); unset when empty.
ValueKind text(std::string ManagerConfig::*field, std::string value_name, std::size_t min_length = 1);

/// true or false (also yes/no, 1/0).
ValueKind boolean(bool ManagerConfig::*field);

/// A numeric IPv4 address; unset when empty.
ValueKind ipv4_address(std::string ManagerConfig::*field);

/// One of `names`, kept as the name.
ValueKind choice(std::string ManagerConfig::*field, std::vector<std::string> names);

/// One of `names`, each standing for a value of `Enum` (the shown name is the first of the value's).
template <typename Enum>
ValueKind enum_choice(Enum ManagerConfig::*field, std::vector<std::pair<std::string, Enum>> names);

/// A value checked by `problem` ("" = fine) and kept as it is; unset when empty.
ValueKind checked_text(std::string ManagerConfig::*field, std::string value_name, std::string range,
                       std::function<std::string(const std::string&)> problem);

/// A secret of 16 characters or more, which messages never echo; shown as kSecretPlaceholder. The placeholder
/// is taken back as "given by the command line or the environment" (parse_manager_args insists on that).
ValueKind secret(std::string ManagerConfig::*field);

/// A list whose entries `problem` checks ("" = fine).
ValueKind checked_list(std::vector<std::string> ManagerConfig::*field, std::string value_name,
                       std::function<std::string(const std::string&)> problem);

/// cluster_peers: ID=ADDRESS:PORT entries, ids and registries each listed once.
ValueKind cluster_peers();

/// A field of the ros: section that `problem` ("" = fine) accepts; unset when empty.
ValueKind ros_text(std::string RosSettings::*field, std::string value_name,
                   std::function<std::string(const std::string&)> problem);

/// A file of the ros: section, made absolute (a session runs in its own folder) and checked by `problem`.
ValueKind ros_file(std::string RosSettings::*field, std::string (*problem)(const std::string& path));

/// One of `names` in the ros: section.
ValueKind ros_choice(std::string RosSettings::*field, const std::vector<std::string>& names);

/// A process limit's count in [0, high], 0 = no limit; `what` names the unit in errors ("MiB").
ValueKind limit_count(std::uint64_t ProcessLimits::*field, std::uint64_t high, std::string value_name,
                      const std::string& what);

// The choices' names as errors and --help say them: the command line's own way (cli/command_line.hpp).
using cli::bar_list;
using cli::spoken_list;

template <typename Enum>
ValueKind enum_choice(Enum ManagerConfig::*field, std::vector<std::pair<std::string, Enum>> names) {
  std::vector<std::string> spoken;
  for (const auto& entry : names) spoken.push_back(entry.first);
  ValueKind kind;
  kind.value_name = bar_list(spoken);
  kind.apply = [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    for (const auto& [name, value] : names) {
      if (v.front() == name) {
        c.*field = value;
        return "";
      }
    }
    return "expected " + spoken_list(spoken);
  };
  kind.show = [=](const ManagerConfig& c) -> std::optional<std::vector<std::string>> {
    for (const auto& [name, value] : names) {
      if (c.*field == value) return std::vector<std::string>{name};
    }
    return std::nullopt;
  };
  return kind;
}

}  // namespace rfbsim::manager::config_table
