// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's settings: the YAML file and the command line, read through one table of keys
// (settings_table), then finished and checked as a whole.
#include "config/config.hpp"

#include <arpa/inet.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>

#include "http/client_address.hpp"
#include "sessions/copy_command.hpp"
#include "sessions/launch_plan.hpp"
#include "config/ros_settings.hpp"
#include "contract/task_bounds.hpp"
#include "contract/validators.hpp"
#include "http/routes.hpp"
#include "admission/start_request.hpp"
#include "cluster/uid_registry.hpp"
#include "config/settings_table.hpp"

namespace rfbsim::manager {

using config_table::find_setting;
using config_table::parse_integer;
using config_table::split_commas;

const char* session_kind_name(SessionKind kind) {
  switch (kind) {
    case SessionKind::kSimRfb:
      return "sim_rfb";
    case SessionKind::kRfb:
      return "rfb";
    case SessionKind::kX11:
      return "x11";
  }
  return "sim_rfb";
}

void finish_config(ManagerConfig& config) {
  // A program's scenarios are its own: unless the config names some for its {scenario}, it has none, and its
  // links need only uid.
  if (config.session_kind != SessionKind::kSimRfb && !config.scenarios_set) config.scenarios.clear();
}

ProcessLimits session_limits(const ManagerConfig& config) {
  ProcessLimits limits = config.limits;
  if (!limits.address_space_set && config.session_kind == SessionKind::kX11) {
    limits.address_space_mb = kDefaultX11AddressSpaceMb;
  }
  return limits;
}

namespace {

// The keys a section of the file holds (connect, token_file, ... for ros), as the table declares them; none for
// a key that is not a section.
std::vector<std::string> section_names(const std::string& section) {
  std::vector<std::string> names;
  if (section.empty()) return names;  // "" names no section (top-level keys have section "")
  for (const config_table::Setting& setting : config_table::settings()) {
    if (config_table::section_of(setting.key) == section) names.push_back(setting.key.substr(section.size() + 1));
  }
  return names;
}

}  // namespace

ConfigOutcome load_config_file(const std::string& path, ManagerConfig base) {
  ConfigOutcome outcome;
  outcome.config = std::move(base);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    outcome.error = path + ": cannot read the file";
    return outcome;
  } catch (const YAML::Exception& error) {
    outcome.error = path + ":" + std::to_string(error.mark.line + 1) + ": " + error.msg;
    return outcome;
  }
  if (root.IsNull()) return outcome;  // an empty file keeps every default
  if (!root.IsMap()) {
    outcome.error = path + ": expected a mapping of settings (key: value)";
    return outcome;
  }
  // One setting from its YAML node: `key` names it in the table, `shown` in messages ("ros.connect").
  const auto apply = [&](const std::string& key, const std::string& shown, const YAML::Node& name,
                         const YAML::Node& node) -> bool {
    const std::string where = path + ":" + std::to_string(name.Mark().line + 1) + ": " + shown + ": ";
    const config_table::Setting* setting = find_setting(key);
    if (setting == nullptr) {
      outcome.error = where + "unknown setting";
      return false;
    }
    std::vector<std::string> values;
    if (setting->kind.list && node.IsSequence()) {
      for (const auto& element : node) {
        if (!element.IsScalar()) {
          outcome.error = where + "expected a list of plain values";
          return false;
        }
        values.push_back(element.Scalar());
      }
    } else if (node.IsScalar()) {
      values.push_back(node.Scalar());
      if (setting->kind.list) values = split_commas(node.Scalar());
    } else {
      outcome.error = where + (setting->kind.list ? "expected a list" : "expected a single value");
      return false;
    }
    if (!setting->kind.list && values.empty()) values.emplace_back();
    const std::string problem = setting->kind.apply(outcome.config, values);
    if (!problem.empty()) {
      outcome.error = where + problem;
      return false;
    }
    return true;
  };
  for (const auto& item : root) {
    if (!item.first.IsScalar()) {
      outcome.error = path + ":" + std::to_string(item.first.Mark().line + 1) + ": expected a setting name as key";
      return outcome;
    }
    const std::string key = item.first.Scalar();
    const std::string line = path + ":" + std::to_string(item.first.Mark().line + 1) + ": ";
    // The ros and x11 sections are mappings of their own (ros: {connect: ...}); their keys are the table's
    // <section>_<key>, which the file names only that way, so that one setting has one spelling there.
    for (const std::string& section : config_table::kSections) {
      if (key.rfind(section + "_", 0) == 0) {
        outcome.error = line + key + ": unknown setting (write it as " + key.substr(section.size() + 1) + ": under " +
                        section + ":)";
        return outcome;
      }
    }
    const std::vector<std::string> names = section_names(key);
    if (names.empty()) {
      if (!apply(key, key, item.first, item.second)) return outcome;
      continue;
    }
    std::string known;
    for (const std::string& name : names) known += (known.empty() ? "" : ", ") + name;
    if (!item.second.IsMap()) {
      outcome.error = line + key + ": expected a mapping (" + known + ")";
      return outcome;
    }
    for (const auto& sub : item.second) {
      const std::string at = path + ":" + std::to_string(sub.first.Mark().line + 1) + ": ";
      if (!sub.first.IsScalar()) {
        outcome.error = at + key + ": expected a setting name as key";
        return outcome;
      }
      const std::string name = sub.first.Scalar();
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        outcome.error = at + key + "." + name + ": unknown setting (known: " + known + ")";
        return outcome;
      }
      if (!apply(key + "_" + name, key + "." + name, sub.first, sub.second)) return outcome;
    }
  }
  return outcome;
}

namespace {

// The uid registry's settings fit together: a secret, this host among the peers, its port the peers know.
std::string cluster_problem(const ManagerConfig& config) {
  if (config.cluster_peers.empty()) {
    if (!config.cluster_secret_file.empty() || config.registry_port != 0 || !config.registry_bind.empty()) {
      return "cluster_secret_file, registry_port and registry_bind need cluster_peers";
    }
    return "";
  }
  if (config.cluster_secret_file.empty()) return "cluster_peers needs cluster_secret_file (the hosts' shared secret)";
  if (config.host_id.empty()) return "cluster_peers needs host_id (this host's id among the peers)";
  const auto self = std::find_if(config.cluster_peers.begin(), config.cluster_peers.end(),
                                 [&](const ClusterPeer& peer) { return peer.id == config.host_id; });
  if (self == config.cluster_peers.end()) return "host_id '" + config.host_id + "' is not one of cluster_peers";
  // A registry answer sends a participant to /<home>/start on the balancer's one origin: every host must own
  // /<its id> there.
  if (config.path_prefix != "/" + config.host_id) {
    return "with cluster_peers, path_prefix must be /" + config.host_id +
           " (other hosts send this host's participants to /<host_id>/start), not '" + config.path_prefix + "'";
  }
  if (!config.public_url.empty()) {
    return "cluster_peers needs the balancer's one origin: leave public_url empty (the registry's redirects are "
           "relative to it)";
  }
  if (config.registry_port != 0 && config.registry_port != self->port) {
    return "registry_port " + std::to_string(config.registry_port) + " differs from this host's cluster_peers entry (" +
           std::to_string(self->port) + ")";
  }
  return "";
}

// The ros section's settings fit together and with the sessions it applies to.
std::string ros_problem(const ManagerConfig& config) {
  const RosSettings& ros = config.ros;
  if (ros.connect.empty()) {
    if (!ros.token_file.empty() || !ros.ca_file.empty()) return "ros: token_file and ca_file need connect";
    // Nothing else can drive an externally controlled robot: sim_manager never opens sim_rfb's own port.
    if (ros.robot_control == "external") return "ros: robot_control external needs connect (the lab's rosbridge)";
    return "";
  }
  if (config.session_kind != SessionKind::kSimRfb) {
    return "ros: needs session_kind sim_rfb (a legacy program's template may use {robot_control} itself)";
  }
  const bool tls = ros.connect.rfind("wss://", 0) == 0;
  if (!ros.ca_file.empty() && !tls) return "ros: ca_file needs a wss:// connect";
  if (!ros.token_file.empty() && !tls) {
    // A Bearer token over plain ws:// is readable by anyone on the path; only loopback is spared that.
    const std::string_view rest = std::string_view(ros.connect).substr(5);
    const std::string_view host = rest.substr(0, rest.find_first_of(":/?#"));
    const bool loopback = host == "127.0.0.1" || host == "localhost" || rest.rfind("[::1]", 0) == 0;
    if (!loopback) return "ros: token_file needs a wss:// connect: over ws:// the token would cross the network in clear";
  }
  return "";
}

}  // namespace

std::string validate_config(const ManagerConfig& config) {
  if (config.tls_certificate.empty() != config.tls_private_key.empty()) {
    return "TLS needs both tls_certificate and tls_private_key";
  }
  if (config.session_kind == SessionKind::kX11) {
    if (config.session_command == "sim_rfb") {
      return "session_kind x11 needs session_command: the X11 program each session runs (e.g. /usr/bin/glxgears)";
    }
    for (const std::string& arg : config.session_args) {
      if (arg.find("{port}") != std::string::npos) {
        return "session_kind x11 has no {port}: the program draws on its own display, which the manager serves";
      }
    }
  }
  if (config.session_kind == SessionKind::kRfb) {
    bool has_port = false;
    for (const std::string& arg : config.session_args) has_port = has_port || arg.find("{port}") != std::string::npos;
    if (!has_port) return "session_kind rfb needs {port} in session_args, where the program is told its port";
  }
  if (config.require_link_expiry && config.link_secret.empty()) {
    return "require_link_expiry needs link_secret: an unsigned exp could simply be edited";
  }
  if (std::string problem = cluster_problem(config); !problem.empty()) return problem;
  // The manager's own flags (where the session listens, its data folder...) are not the config's to change.
  if (std::string problem = session_args_problem(config.session_args, config.session_kind); !problem.empty()) {
    return problem;
  }
  if (std::string problem = copy_command_problem(config.after_session_command); !problem.empty()) return problem;
  if (std::string problem = ros_problem(config); !problem.empty()) return problem;
  return "";
}

namespace {

// The task's time limit a session of `facts` runs with, s: sim_rfb takes the last --time-limit S of its
// arguments over the scenario's.
double task_time_limit(const ManagerConfig& config, const ScenarioFacts& facts) {
  double limit = facts.time_limit_s;
  constexpr long long kLow = contract::kMinTimeLimitS;  // sim_rfb's bounds for the flag and the scenario's key
  constexpr long long kHigh = contract::kMaxTimeLimitS;
  for (std::size_t i = 0; config.session_kind == SessionKind::kSimRfb && i + 1 < config.session_args.size(); ++i) {
    long long value = 0;
    if (config.session_args[i] == "--time-limit" && parse_integer(config.session_args[i + 1], kLow, kHigh, value)) {
      limit = static_cast<double>(value);
    }
  }
  return limit;
}

}  // namespace

std::chrono::seconds session_time_needed(const ManagerConfig& config, const ScenarioFacts& facts) {
  if (!facts.has_task) return std::chrono::seconds(0);
  // The latest the clock can start: a first browser is waited for this long after /start, and the relay
  // reaches sim_rfb once it is ready, which may take until start_timeout.
  const auto first_browser = std::min(config.first_connect_timeout, config.idle_timeout);
  const auto clock_start = std::max(config.start_timeout, first_browser);
  const double seconds = static_cast<double>((clock_start + kSessionEndMargin).count()) +
                         task_time_limit(config, facts) + facts.end_grace_s;
  return std::chrono::seconds(static_cast<long long>(std::ceil(seconds - 1e-9)));
}

std::string fit_max_duration(ManagerConfig& config) {
  std::string warning;
  const std::chrono::seconds chosen = config.max_duration;
  for (const ScenarioFacts& facts : config.scenario_facts) {
    const std::chrono::seconds needed = session_time_needed(config, facts);
    if (!config.max_duration_set) {
      config.max_duration = std::max(config.max_duration, needed);
    } else if (needed > chosen) {
      warning += std::string(warning.empty() ? "" : "; ") + "max_duration_s " + std::to_string(chosen.count()) +
                 " can end a session of " + facts.name + " before its task does (it needs " +
                 std::to_string(needed.count()) + " s: the start, a time limit of " +
                 std::to_string(static_cast<long long>(std::ceil(task_time_limit(config, facts)))) + " s and an end grace of " +
                 std::to_string(static_cast<long long>(std::ceil(facts.end_grace_s))) + " s; docs/deployment.md)";
    }
  }
  return warning;
}

}  // namespace rfbsim::manager
