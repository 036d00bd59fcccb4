// SPDX-License-Identifier: GPL-2.0-or-later
#include "config/settings_table.hpp"

#include "rfbsim/log.hpp"

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

namespace rfbsim::manager::config_table {

namespace {

// limits.cpu_slack_s's bound: a day of CPU beyond the session's share (a guard against typos, not a task bound).
constexpr long long kMaxCpuSlackS = 24LL * 3600;

Apply integer(int ManagerConfig::*field, int low, int high) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    if (!parse_integer(v.front(), low, high, c.*field)) {
      return "expected an integer " + std::to_string(low) + ".." + std::to_string(high);
    }
    return "";
  };
}

Apply seconds(std::chrono::seconds ManagerConfig::*field, long long low) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    long long value = 0;
    if (!parse_integer(v.front(), low, 7LL * 24 * 3600, value)) {
      return "expected whole seconds " + std::to_string(low) + ".." + std::to_string(7 * 24 * 3600);
    }
    c.*field = std::chrono::seconds(value);
    return "";
  };
}

// An integer field of the abuse limits.
Apply abuse_integer(int AbuseLimits::*field, int high) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    if (!parse_integer(v.front(), 0, high, c.abuse.*field)) return "expected 0.." + std::to_string(high) + ", 0 = off";
    return "";
  };
}

Apply abuse_seconds(std::chrono::seconds AbuseLimits::*field) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    long long value = 0;
    if (!parse_integer(v.front(), 0LL, 3600LL, value)) return "expected whole seconds 0..3600, 0 = off";
    c.abuse.*field = std::chrono::seconds(value);
    return "";
  };
}

Apply text(std::string ManagerConfig::*field, std::size_t min_length = 1) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    if (v.front().size() < min_length) {
      return min_length <= 1 ? "must not be empty" : "must be at least " + std::to_string(min_length) + " characters";
    }
    c.*field = v.front();
    return "";
  };
}

// A file of the ros section, made absolute (a session runs in its own folder) and checked by `problem`.
Apply ros_file(std::string RosSettings::*field, std::string (*problem)(const std::string& path)) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    if (v.front().empty()) return "must not be empty";
    std::error_code ec;
    const std::string path = std::filesystem::absolute(v.front(), ec).string();
    if (ec) return "cannot make " + v.front() + " absolute: " + ec.message();
    if (std::string found = problem(path); !found.empty()) return found;
    c.ros.*field = path;
    return "";
  };
}

Apply boolean(bool ManagerConfig::*field) {
  return [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
    if (v.front() == "true" || v.front() == "yes" || v.front() == "1") {
      c.*field = true;
    } else if (v.front() == "false" || v.front() == "no" || v.front() == "0") {
      c.*field = false;
    } else {
      return "expected true or false";
    }
    return "";
  };
}

// An origin as browsers send it, scheme://host[:port] and nothing after: frame origins are compared with the
// Origin header byte for byte (the contract's rule, of the same shape as sim_rfb's --allow-origin).
bool is_origin(const std::string& origin) { return contract::is_browser_origin(origin); }

// A host name as DNS compares it: ASCII letters without case.
std::string lower_case(std::string text) {
  for (char& ch : text) {
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  }
  return text;
}

// "ID=ADDRESS:PORT", one entry of cluster_peers.
std::optional<ClusterPeer> parse_cluster_peer(const std::string& entry) {
  const std::size_t eq = entry.find('=');
  const std::size_t colon = entry.rfind(':');
  if (eq == std::string::npos || colon == std::string::npos || colon < eq) return std::nullopt;
  ClusterPeer peer;
  peer.id = entry.substr(0, eq);
  peer.address = entry.substr(eq + 1, colon - eq - 1);
  if (!is_host_id(peer.id) || !parse_integer(entry.substr(colon + 1), 1, 65535, peer.port)) return std::nullopt;
  // A host name or a numeric IPv4 address: letters, digits, dots and dashes.
  if (peer.address.empty() || peer.address.size() > 253) return std::nullopt;
  for (const char ch : peer.address) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
                    ch == '-';
    if (!ok) return std::nullopt;
  }
  return peer;
}

}  // namespace

const std::map<std::string, Setting>& settings() {
  static const std::map<std::string, Setting> table = {
      {"listen_address", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         in_addr address{};
         if (::inet_pton(AF_INET, v.front().c_str(), &address) != 1) return "expected a numeric IPv4 address";
         c.listen_address = v.front();
         return "";
       }}},
      {"port", {false, integer(&ManagerConfig::port, 0, 65535)}},
      {"tls_certificate", {false, text(&ManagerConfig::tls_certificate)}},
      {"tls_private_key", {false, text(&ManagerConfig::tls_private_key)}},
      {"session_command", {false, text(&ManagerConfig::session_command)}},
      {"session_kind", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() == "sim_rfb") {
           c.session_kind = SessionKind::kSimRfb;
         } else if (v.front() == "rfb") {
           c.session_kind = SessionKind::kRfb;
         } else if (v.front() == "x11") {
           c.session_kind = SessionKind::kX11;
         } else {
           return "expected sim_rfb, rfb or x11";
         }
         return "";
       }}},
      {"session_args", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         c.session_args = v;
         return "";
       }}},
      {"codec", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() != "auto" && v.front() != "jpeg" && v.front() != "h264") return "expected auto, jpeg or h264";
         c.codec = v.front();
         return "";
       }}},
      {"log_level", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         rfbsim::log::Level level{};
         if (!rfbsim::log::parse_level(v.front(), level)) return "expected error, warn, info or debug";
         c.log_level = v.front();
         return "";
       }}},
      {"session_socket", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() != "unix" && v.front() != "tcp") return "expected unix or tcp";
         c.session_socket = v.front();
         return "";
       }}},
      {"max_sessions", {false, integer(&ManagerConfig::max_sessions, 1, 10000)}},
      {"max_duration_s", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         c.max_duration_set = true;  // the researcher's own limit: fit_max_duration keeps it
         return seconds(&ManagerConfig::max_duration, 1)(c, v);
       }}},
      {"idle_timeout_s", {false, seconds(&ManagerConfig::idle_timeout, 1)}},
      {"first_connect_timeout_s", {false, seconds(&ManagerConfig::first_connect_timeout, 1)}},
      {"start_timeout_s", {false, seconds(&ManagerConfig::start_timeout, 1)}},
      {"stop_grace_s", {false, seconds(&ManagerConfig::stop_grace, 0)}},
      {"data_dir", {false, text(&ManagerConfig::data_dir)}},
      {"scenarios", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.empty()) return "list at least one scenario";
         for (const std::string& entry : v) {
           const std::string name = entry.substr(0, entry.find('='));
           if (!is_identifier(name)) {
             return "'" + entry + "' is not a scenario name (letters, digits, - and _, at most 64), optionally =FILE";
           }
         }
         c.scenarios = v;
         c.scenarios_set = true;
         return "";
       }}},
      {"frame_origins", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         for (const std::string& origin : v) {
           if (!is_origin(origin)) {
             return "'" + origin + "' is not an origin such as https://survey.example.org (lower case, no path)";
           }
         }
         c.frame_origins = v;
         return "";
       }}},
      {"admin_token", {false, text(&ManagerConfig::admin_token, 16)}},
      {"link_secret", {false, text(&ManagerConfig::link_secret, 16)}},
      {"allow_repeat", {false, boolean(&ManagerConfig::allow_repeat)}},
      {"require_link_expiry", {false, boolean(&ManagerConfig::require_link_expiry)}},
      {"host_id", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!is_identifier(v.front())) return "expected letters, digits, - and _ (at most 64)";
         c.host_id = v.front();
         return "";
       }}},
      {"web_root", {false, text(&ManagerConfig::web_root)}},
      {"public_url", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!is_origin(v.front())) return "expected an origin such as https://h1.study.example.org (no path)";
         c.public_url = v.front();
         return "";
       }}},
      {"path_prefix", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!is_path_prefix(v.front())) return "expected / and 1-32 of a-z, 0-9 and - (e.g. /h2)";
         c.path_prefix = v.front();
         return "";
       }}},
      {"agent_port", {false, integer(&ManagerConfig::agent_port, 0, 65535)}},
      {"agent_bind", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         in_addr address{};
         if (::inet_pton(AF_INET, v.front().c_str(), &address) != 1) return "expected a numeric IPv4 address";
         c.agent_bind = v.front();
         return "";
       }}},
      {"limit_address_space_mb", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!parse_integer<std::uint64_t>(v.front(), 0, 1ULL << 30, c.limits.address_space_mb)) {
           return "expected MiB, 0 = no limit";
         }
         c.limits.address_space_set = true;
         return "";
       }}},
      {"limit_open_files", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!parse_integer<std::uint64_t>(v.front(), 0, 1ULL << 20, c.limits.open_files)) {
           return "expected a count, 0 = no limit";
         }
         return "";
       }}},
      {"limit_cpu_time_factor", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         double factor = 0;
         const char* end = v.front().data() + v.front().size();
         const auto [ptr, ec] = std::from_chars(v.front().data(), end, factor);
         if (v.front().empty() || ec != std::errc() || ptr != end || !std::isfinite(factor) || factor < 0 ||
             factor > 256) {
           return "expected cores per session 0..256, 0 = no CPU limit";
         }
         c.limits.cpu_time_factor = factor;
         return "";
       }}},
      {"rate_start_per_minute", {false, abuse_integer(&AbuseLimits::start_per_minute, 1000000)}},
      {"rate_start_burst", {false, abuse_integer(&AbuseLimits::start_burst, 1000000)}},
      {"rate_upgrade_per_minute", {false, abuse_integer(&AbuseLimits::upgrade_per_minute, 1000000)}},
      {"rate_upgrade_burst", {false, abuse_integer(&AbuseLimits::upgrade_burst, 1000000)}},
      {"max_connections_per_address", {false, abuse_integer(&AbuseLimits::connections_per_address, 1000000)}},
      {"max_connections", {false, abuse_integer(&AbuseLimits::connections_total, 1000000)}},
      {"max_unspent_sessions_per_address", {false, abuse_integer(&AbuseLimits::unspent_sessions_per_address, 1000000)}},
      {"ws_ping_interval_s", {false, abuse_seconds(&AbuseLimits::ws_ping_interval)}},
      {"ws_pong_timeout_s", {false, abuse_seconds(&AbuseLimits::ws_pong_timeout)}},
      {"trusted_proxies", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         for (const std::string& entry : v) {
           if (!parse_address_range(entry)) return "'" + entry + "' is not an address or CIDR range such as 10.0.0.0/8";
         }
         c.trusted_proxies = v;
         return "";
       }}},
      {"on_data_incomplete", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() == "continue") {
           c.on_data_incomplete = DataFailurePolicy::kContinue;
         } else if (v.front() == "end") {
           c.on_data_incomplete = DataFailurePolicy::kEnd;
         } else {
           return "expected continue or end";
         }
         return "";
       }}},
      {"cluster_peers", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         std::vector<ClusterPeer> peers;
         for (const std::string& entry : v) {
           const auto peer = parse_cluster_peer(entry);
           if (!peer) return "'" + entry + "' is not ID=ADDRESS:PORT (ID: 1-32 of a-z 0-9 -, PORT: 1..65535)";
           for (const ClusterPeer& other : peers) {
             if (other.id == peer->id) return "host id '" + peer->id + "' is listed twice";
             // Two ids at one registry would be one acceptor voting twice: majorities would no longer intersect.
             if (other.port == peer->port && lower_case(other.address) == lower_case(peer->address)) {
               return "hosts '" + other.id + "' and '" + peer->id + "' have the same registry " + peer->address + ":" +
                      std::to_string(peer->port);
             }
           }
           peers.push_back(*peer);
         }
         c.cluster_peers = std::move(peers);
         return "";
       }}},
      {"cluster_secret_file", {false, text(&ManagerConfig::cluster_secret_file)}},
      {"registry_port", {false, integer(&ManagerConfig::registry_port, 1, 65535)}},
      {"registry_bind", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         in_addr address{};
         if (::inet_pton(AF_INET, v.front().c_str(), &address) != 1) return "expected a numeric IPv4 address";
         c.registry_bind = v.front();
         return "";
       }}},
      {"after_session_command", {true, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (std::string problem = copy_command_problem(v); !problem.empty()) return problem;
         c.after_session_command = v;
         return "";
       }}},
      {"after_session_retries", {false, integer(&ManagerConfig::after_session_retries, 0, 100)}},
      {"after_session_timeout_s", {false, seconds(&ManagerConfig::after_session_timeout, 1)}},
      // The ros: section, each key as ros_<key> (--ros-<key> on the command line); files made absolute, since a
      // session runs in its own folder.
      {"ros_connect", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (std::string problem = rosbridge_url_problem(v.front()); !problem.empty()) return problem;
         c.ros.connect = v.front();
         return "";
       }}},
      {"ros_token_file", {false, ros_file(&RosSettings::token_file, token_file_problem)}},
      {"ros_ca_file", {false, ros_file(&RosSettings::ca_file, ca_file_problem)}},
      {"ros_namespace", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (!is_ros_name(v.front())) {
           return "expected a ROS name such as /rfbsim: '/', then segments of letters, digits and '_' that start "
                  "with a letter, joined by '/', no '/' at the end";
         }
         c.ros.ros_namespace = v.front();
         return "";
       }}},
      {"ros_robot_control", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() != "builtin" && v.front() != "external") return "expected builtin or external";
         c.ros.robot_control = v.front();
         return "";
       }}},
      {"ros_cmd_vel_type", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front() != "twist" && v.front() != "twist_stamped") return "expected twist or twist_stamped";
         c.ros.cmd_vel_type = v.front();
         return "";
       }}},
      {"limit_cpu_slack_s", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         long long value = 0;
         if (!parse_integer(v.front(), 0LL, kMaxCpuSlackS, value)) {
           return "expected whole seconds 0.." + std::to_string(kMaxCpuSlackS);
         }
         c.limits.cpu_slack = std::chrono::seconds(value);
         return "";
       }}},
      // The x11 section (x11: {geometry, depth, xvnc}): the display each x11 session's program runs on.
      {"x11_geometry", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         const std::string& text = v.front();
         const std::size_t x = text.find('x');
         int width = 0;
         int height = 0;
         // Xvnc needs whole pixels; a screen past 8192 would cost a participant's link more than any program.
         if (x == std::string::npos || !parse_integer(text.substr(0, x), 64, 8192, width) ||
             !parse_integer(text.substr(x + 1), 64, 8192, height)) {
           return "expected WIDTHxHEIGHT, each 64..8192 (e.g. 1280x720)";
         }
         c.x11.width = width;
         c.x11.height = height;
         return "";
       }}},
      {"x11_depth", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         int depth = 0;
         if (!parse_integer(v.front(), 16, 24, depth) || (depth != 16 && depth != 24)) return "expected 16 or 24";
         c.x11.depth = depth;
         return "";
       }}},
      {"x11_xvnc", {false, [](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
         if (v.front().empty() || v.front().front() != '/') return "expected the absolute path of TigerVNC's Xvnc";
         c.x11.xvnc = v.front();
         return "";
       }}},
  };
  return table;
}

std::string flag_to_key(const std::string& flag) {
  std::string key = flag.substr(2);
  for (char& ch : key) {
    if (ch == '-') ch = '_';
  }
  return key;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    parts.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (parts.size() == 1 && parts.front().empty()) parts.clear();
  return parts;
}

}  // namespace rfbsim::manager::config_table
