// SPDX-License-Identifier: GPL-2.0-or-later
// Validation of /start links.
#include "admission/start_request.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace rfbsim::manager {

const std::vector<OverrideParam> kOverrideParams = {
    {"avatar_start", "--avatar-start"}, {"avatar_goal", "--avatar-goal"}, {"robot_start", "--robot-start"},
    {"robot_goal", "--robot-goal"},     {"crowd", "--crowd"},       {"robot_control", "--robot-control"},
    {"camera", "--camera"},
};

namespace {

// Maps are tens of metres; anything beyond this is a typo or an attack, not a pose.
constexpr double kMaxCoordinate = 10000.0;
constexpr double kMaxYaw = 7.0;  // a little over 2 pi
constexpr int kMaxCrowd = 500;  // sim_rfb's own bound

// "-12.5": an optional minus, digits, optionally a point and digits. No exponents, spaces or "+".
std::optional<double> strict_decimal(std::string_view text) {
  if (text.empty() || text.size() > 16) return std::nullopt;
  std::size_t i = text[0] == '-' ? 1 : 0;
  bool digits_before = false;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    ++i;
    digits_before = true;
  }
  if (!digits_before) return std::nullopt;
  if (i < text.size()) {
    if (text[i] != '.' || i + 1 == text.size()) return std::nullopt;
    for (++i; i < text.size(); ++i) {
      if (text[i] < '0' || text[i] > '9') return std::nullopt;
    }
  }
  double value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

bool is_count(std::string_view text, int high) {
  // Digits only: from_chars alone would take "-0".
  if (text.empty() || text.size() > 4 || text.front() < '0' || text.front() > '9') return false;
  int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && ptr == text.data() + text.size() && value >= 0 && value <= high;
}

std::optional<std::uint64_t> strict_seed(std::string_view text) {
  if (text.empty() || text.size() > 20) return std::nullopt;
  for (const char ch : text) {
    if (ch < '0' || ch > '9') return std::nullopt;
  }
  std::uint64_t value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size()) return std::nullopt;
  return value;
}

// Parameter values are echoed in error pages: cut them short (pages escape them too).
std::string shown(const std::string& value) { return value.size() > 40 ? value.substr(0, 40) + "..." : value; }

// What a pose override names, if a spawn point: the pose forms are an identifier or x,y,yaw.
bool names_spawn(const std::string& value) { return is_identifier(value); }

}  // namespace


bool is_pose(std::string_view text) {
  if (is_identifier(text)) return true;
  const std::size_t first = text.find(',');
  if (first == std::string_view::npos) return false;
  const std::size_t second = text.find(',', first + 1);
  if (second == std::string_view::npos || text.find(',', second + 1) != std::string_view::npos) return false;
  const auto x = strict_decimal(text.substr(0, first));
  const auto y = strict_decimal(text.substr(first + 1, second - first - 1));
  const auto yaw = strict_decimal(text.substr(second + 1));
  return x && y && yaw && std::fabs(*x) <= kMaxCoordinate && std::fabs(*y) <= kMaxCoordinate &&
         std::fabs(*yaw) <= kMaxYaw;
}

std::vector<std::string> scenario_names(const std::vector<std::string>& entries) {
  std::vector<std::string> names;
  for (const std::string& entry : entries) names.push_back(entry.substr(0, entry.find('=')));
  return names;
}

std::string scenario_argument(const std::vector<std::string>& entries, const std::string& name) {
  for (const std::string& entry : entries) {
    const std::size_t eq = entry.find('=');
    if (entry.substr(0, eq) == name) return eq == std::string::npos ? entry : entry.substr(eq + 1);
  }
  return name;
}

StartParse parse_start_request(const QueryParams& params, const std::vector<std::string>& scenarios) {
  StartParse out;
  StartRequest request;
  bool have_uid = false;
  bool have_scenario = false;
  for (const auto& [name, value] : params) {
    if (name == "sig") continue;
    if (name == "uid") {
      if (!is_identifier(value)) {
        out.error = "uid '" + shown(value) + "' is not valid: use 1 to 64 letters, digits, '-' or '_'";
        return out;
      }
      request.uid = value;
      have_uid = true;
    } else if (name == "scenario") {
      if (scenarios.empty()) {
        out.error = "scenario '" + shown(value) + "' is not offered here: this server's program has no scenarios, and "
                    "its links need only uid";
        return out;
      }
      if (std::find(scenarios.begin(), scenarios.end(), value) == scenarios.end() || !is_identifier(value)) {
        std::string allowed;
        for (const std::string& s : scenarios) allowed += (allowed.empty() ? "" : ", ") + s;
        out.error = "scenario '" + shown(value) + "' is not offered here (allowed: " + allowed + ")";
        return out;
      }
      request.scenario = value;
      have_scenario = true;
    } else if (name == "t1" || name == "t2") {
      if (!is_identifier(value)) {
        out.error = name + " '" + shown(value) + "' is not valid: use 1 to 64 letters, digits, '-' or '_'";
        return out;
      }
      (name == "t1" ? request.code_success : request.code_timeout) = value;
    } else if (name == "exp") {
      request.expires_at = strict_seed(value);  // the same rule: a plain whole number, no sign, no spaces
      if (!request.expires_at) {
        out.error = "exp '" + shown(value) + "' is not valid: use a Unix time in whole seconds";
        return out;
      }
    } else if (name == "condition") {
      if (value != "interactive" && value != "video") {
        out.error = "condition '" + shown(value) + "' is not valid: use interactive or video";
        return out;
      }
      request.condition = value;
    } else if (name == "yoke_uid") {
      if (!is_identifier(value)) {
        out.error = "yoke_uid '" + shown(value) + "' is not valid: use 1 to 64 letters, digits, '-' or '_'";
        return out;
      }
      request.yoke_uid = value;
    } else if (name == "seed") {
      request.seed = strict_seed(value);
      if (!request.seed) {
        out.error = "seed '" + shown(value) + "' is not valid: use a whole number 0..18446744073709551615";
        return out;
      }
    } else {
      const auto known = std::find_if(kOverrideParams.begin(), kOverrideParams.end(),
                                      [&name = name](const OverrideParam& p) { return name == p.name; });
      if (known == kOverrideParams.end()) {
        out.error = "unknown parameter '" + shown(name) + "'";
        return out;
      }
      // Who drives the robot: the simulator's own planner, or /cmd_vel from a lab's ROS stack (issue 20).
      if (name == "robot_control") {
        if (value != "builtin" && value != "external") {
          out.error = "robot_control '" + shown(value) + "' is not valid: use builtin or external";
          return out;
        }
        continue;
      }
      // The participant's view (issue 33); a study that fixes it refuses the parameter (StartAdmission).
      if (name == "camera") {
        if (value != "third_person" && value != "first_person") {
          out.error = "camera '" + shown(value) + "' is not valid: use third_person or first_person";
          return out;
        }
        continue;
      }
      const bool crowd = name == "crowd";
      if (crowd ? !is_count(value, kMaxCrowd) : !is_pose(value)) {
        out.error = name + " '" + shown(value) + "' is not valid: " +
                    (crowd ? "use a whole number 0.." + std::to_string(kMaxCrowd)
                           : std::string("use a spawn point's name or x,y,yaw in metres and radians"));
        return out;
      }
    }
  }
  if (!have_uid) {
    out.error = "the link has no uid (participant id)";
    return out;
  }
  if (request.condition != "video" && !request.yoke_uid.empty()) {
    out.error = "yoke_uid is for condition=video links only";
    return out;
  }
  // A watcher is shown the recorded session as it was: its seed, poses, crowd, robot and view are the walker's.
  if (request.condition == "video") {
    for (const auto& [name, value] : params) {
      const bool sets_world = name == "seed" || std::any_of(kOverrideParams.begin(), kOverrideParams.end(),
                                                            [&name = name](const OverrideParam& p) { return name == p.name; });
      if (!sets_world) continue;
      out.error = name + " is not valid with condition=video: the watcher is shown the recorded session as it was";
      return out;
    }
  }
  // Without a list (a program's session kind that names none) a session has no scenario.
  if (!have_scenario && !scenarios.empty()) request.scenario = scenarios.front();
  // Overrides in a fixed order, so that equal links give equal command lines and index rows.
  for (const OverrideParam& param : kOverrideParams) {
    for (const auto& [name, value] : params) {
      if (name == param.name) request.overrides.emplace_back(name, value);
    }
  }
  out.request = std::move(request);
  return out;
}

StartParse parse_start_request(const QueryParams& params, const std::vector<std::string>& scenarios,
                               const std::vector<ScenarioFacts>& facts) {
  StartParse out = parse_start_request(params, scenarios);
  if (!out.request) return out;
  const StartRequest& request = *out.request;
  const auto known = std::find_if(facts.begin(), facts.end(),
                                  [&request](const ScenarioFacts& f) { return f.name == request.scenario; });
  if (known == facts.end()) return out;
  // sim_rfb would refuse these at start-up, after the participant's slot, process and wait: say it now.
  for (const auto& [name, value] : request.overrides) {
    if (name == "crowd") continue;
    if ((name == "robot_start" || name == "robot_goal" || name == "robot_control") && !known->has_robot) {
      out.error = name + " is not valid here: scenario " + known->name + " has no robot";
      out.request.reset();
      return out;
    }
    if (name == "robot_control" || name == "camera") continue;  // modes, not poses
    if (!names_spawn(value) || std::count(known->spawns.begin(), known->spawns.end(), value) > 0) continue;
    std::string names;
    for (const std::string& spawn : known->spawns) names += (names.empty() ? "" : ", ") + spawn;
    out.error = name + " '" + shown(value) + "' is not a spawn point of " + known->name +
                " (known: " + (names.empty() ? std::string("none") : names) + "; or give x,y,yaw)";
    out.request.reset();
    return out;
  }
  return out;
}

}  // namespace rfbsim::manager
