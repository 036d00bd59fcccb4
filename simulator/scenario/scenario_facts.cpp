// SPDX-License-Identifier: GPL-2.0-or-later
// Reading ScenarioFacts (what sim_manager needs) from scenario files.
#include "scenario/scenario_facts.hpp"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "contract/task_bounds.hpp"
#include "contract/validators.hpp"

namespace rfbsim::sim {

namespace {

// "<file>:<line>: <key>: " for an error about one node of a scenario file.
std::string where(const std::string& file, const YAML::Node& node, const std::string& key) {
  return file + ":" + std::to_string(node.Mark().line + 1) + ": " + key + ": ";
}

// A number of seconds from a YAML scalar, within [low, high] (sim_rfb's bounds for the same key).
std::optional<double> seconds_value(const YAML::Node& node, double low, double high) {
  if (!node.IsScalar()) return std::nullopt;
  const std::string& text = node.Scalar();
  double value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value) || value < low ||
      value > high) {
    return std::nullopt;
  }
  return value;
}

// `task.<key>` into `out` when present: seconds within [low, high], else false with `error` naming the file,
// the line and the key.
bool read_seconds(const YAML::Node& task, const char* key, double low, double high, const std::string& file,
                  double& out, std::string& error) {
  const YAML::Node node = task[key];
  if (!node) return true;
  const auto value = seconds_value(node, low, high);
  if (!value) {
    char range[48];
    std::snprintf(range, sizeof range, "expected seconds %g..%g", low, high);
    error = where(file, node, std::string("task.") + key) + range;
    return false;
  }
  out = *value;
  return true;
}

}  // namespace

std::optional<ScenarioFacts> parse_scenario_facts(const std::string& text, const std::string& name,
                                                  const std::string& file, std::string& error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    error = file + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg;
    return std::nullopt;
  }
  if (!root.IsMap()) {
    error = file + ": expected a mapping of scenario keys";
    return std::nullopt;
  }
  ScenarioFacts facts;
  facts.name = name;
  facts.file = file;
  if (const YAML::Node spawns = root["spawns"]) {
    if (!spawns.IsMap()) {
      error = where(file, spawns, "spawns") + "expected a mapping of names to poses";
      return std::nullopt;
    }
    for (const auto& spawn : spawns) {
      // A name no link can carry (not an identifier) is sim_rfb's business, not a reason to stop the manager.
      if (!spawn.first.IsScalar() || !contract::is_identifier(spawn.first.Scalar())) continue;
      facts.spawns.push_back(spawn.first.Scalar());
    }
  }
  facts.has_robot = static_cast<bool>(root["robot"]);
  if (facts.has_robot && root["robot"].IsMap()) {
    const YAML::Node control = root["robot"]["control"];
    if (control && control.IsScalar() && control.Scalar() == "external") facts.robot_control = "external";
  }
  if (const YAML::Node task = root["task"]) {
    if (!task.IsMap()) {
      error = where(file, task, "task") + "expected a mapping (time_limit, end_grace, steps)";
      return std::nullopt;
    }
    facts.has_task = true;
    if (!read_seconds(task, "time_limit", contract::kMinTimeLimitS, contract::kMaxTimeLimitS, file, facts.time_limit_s,
                      error) ||
        !read_seconds(task, "end_grace", contract::kMinEndGraceS, contract::kMaxEndGraceS, file, facts.end_grace_s,
                      error)) {
      return std::nullopt;
    }
  }
  return facts;
}

std::vector<ScenarioFacts> load_scenario_facts(const std::vector<std::string>& entries,
                                               const std::vector<std::filesystem::path>& search_dirs,
                                               std::string& error, std::vector<std::string>& missing) {
  std::vector<ScenarioFacts> all;
  for (const std::string& entry : entries) {
    const std::size_t eq = entry.find('=');
    const std::string name = entry.substr(0, eq);
    std::filesystem::path file;
    std::error_code ec;
    if (eq != std::string::npos) {
      file = entry.substr(eq + 1);
    } else {
      for (const auto& dir : search_dirs) {
        if (!dir.empty() && std::filesystem::is_regular_file(dir / (name + ".yaml"), ec)) {
          file = dir / (name + ".yaml");
          break;
        }
      }
    }
    if (file.empty()) {
      missing.push_back(entry);
      continue;
    }
    // A file named in the config must be there: every session of it would fail otherwise.
    std::ifstream in(file);
    std::ostringstream text;
    if (std::filesystem::is_regular_file(file, ec) && in) text << in.rdbuf();
    if (!std::filesystem::is_regular_file(file, ec) || !in || in.bad()) {
      error = "scenarios: " + entry + ": cannot read " + file.string();
      return all;
    }
    auto facts = parse_scenario_facts(text.str(), name, file.string(), error);
    if (!facts) return all;
    all.push_back(std::move(*facts));
  }
  return all;
}

}  // namespace rfbsim::sim
