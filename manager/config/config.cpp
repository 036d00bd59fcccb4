// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's settings: one table of keys serves the YAML file and the command line alike.
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

namespace rfbsim::manager {

namespace {

// limits.cpu_slack_s's bound: a day of CPU beyond the session's share (a guard against typos, not a task bound).
constexpr long long kMaxCpuSlackS = 24LL * 3600;

// Applies a setting's values (one for a scalar, any number for a list); returns "" or what is wrong.
using Apply = std::function<std::string(ManagerConfig&, const std::vector<std::string>&)>;

struct Setting {
  bool list = false;  // YAML sequence / comma-separated flag value
  Apply apply;
};

template <typename T>
bool parse_integer(const std::string& text, T low, T high, T& out) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < low || value > high) return false;
  out = value;
  return true;
}

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

}  // namespace

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

std::string manager_usage() {
  return "usage: sim_manager [--config FILE] [--listen-address ADDR] [--port N] [--tls-certificate PEM]\n"
         "                   [--tls-private-key PEM] [--session-command PROGRAM] [--session-kind sim_rfb|rfb|x11]\n"
         "                   [--session-arg ARG]... [--codec auto|jpeg|h264] [--max-sessions N]\n"
         "                   [--max-duration-s S] [--idle-timeout-s S]\n"
         "                   [--data-dir DIR] [--scenarios A,B] [--frame-origins O1,O2] [--admin-token T]\n"
         "                   [--link-secret S] [--allow-repeat true|false] [--host-id ID] [--web-root DIR]\n"
         "                   [--public-url ORIGIN] [--path-prefix /ID] [--agent-port N] [--agent-bind ADDR]\n"
         "       sim_manager [--config FILE] --sign 'uid=...&scenario=...'\n"
         "Every flag is also a key of the YAML config file (--max-sessions N is max_sessions: N).\n"
         "  --listen-address ADDR   numeric IPv4 address (default 127.0.0.1)\n"
         "  --port N                the one public port (default 8080; 0 = any free port)\n"
         "  --tls-certificate F, --tls-private-key F   serve HTTPS and WSS (OpenSSL)\n"
         "  --session-command P     program started per session (default: sim_rfb)\n"
         "  --session-kind K        sim_rfb (default); rfb: any program that serves raw RFB on the port\n"
         "                          given as {port} in its --session-arg list (one linking librfbsim); or x11:\n"
         "                          any X11 program, each session on its own Xvnc display (the x11: section)\n"
         "  --session-arg A         one more argument for the session program (repeat as needed)\n"
         "  --codec C               sim_rfb's picture encoding: auto (default: Tight JPEG, H.264 for a browser\n"
         "                          that offers it once its link needs it), jpeg, or h264 (H.264 for every\n"
         "                          browser that offers it; noVNC 1.6+ needs https or localhost for it)\n"
         "  --session-socket unix|tcp   how the relay reaches a sim_rfb session: a private unix socket (default)\n"
         "                          or a loopback TCP port\n"
         "  --max-sessions N        live sessions at once (default 4)\n"
         "  --max-duration-s S      a session ends S seconds after /start (default 300, or longer when a\n"
         "                          scenario's task needs it: its start, time limit and end grace)\n"
         "  --idle-timeout-s S      a session ends after S seconds with no browser connected (default 60)\n"
         "  --first-connect-timeout-s S   a session no browser ever connected to ends S seconds after /start\n"
         "                          (default 20; the idle timeout when that is shorter)\n"
         "  --start-timeout-s S     a session not ready after S seconds failed (default 30)\n"
         "  --stop-grace-s S        seconds between SIGTERM and SIGKILL (default 5)\n"
         "  --data-dir DIR          session index and session folders (default ./rfbsim-data)\n"
         "  --scenarios A,B         scenarios a link may ask for; NAME or NAME=FILE (default warehouse,lab)\n"
         "  --frame-origins O1,O2   origins allowed to frame the page, e.g. https://survey.example.org\n"
         "  --admin-token T         enables /admin and /api/sessions (or RFBSIM_ADMIN_TOKEN; 16+ chars)\n"
         "  --link-secret S         /start links must be signed (or RFBSIM_LINK_SECRET; 16+ chars)\n"
         "  --allow-repeat B        a uid whose session ended may start another (default false)\n"
         "  --require-link-expiry B signed links must carry exp=UNIX_SECONDS, and expire then (default false)\n"
         "  --host-id ID            this host's name in the index (default: the host name)\n"
         "  --web-root DIR          the participant page (default: the built or installed one)\n"
         "  --public-url ORIGIN     this host's public origin; /start redirects there (several hosts)\n"
         "  --path-prefix /ID       this host's part of a balancer's URL space (e.g. /h2): pages, sockets and the\n"
         "                          admin API answer under it, /start redirects into it (default: none, or\n"
         "                          /HOST_ID with cluster peers)\n"
         "  --agent-port N          HAProxy agent-check port: \"up ready NN%\" or \"drain\" (default 0 = off)\n"
         "  --agent-bind ADDR       the agent port's numeric IPv4 address (default: the listen address)\n"
         "  --limit-address-space-mb N, --limit-open-files N, --limit-cpu-time-factor F, --limit-cpu-slack-s S\n"
         "                          per-session resource limits (0 = none)\n"
         "  --rate-start-per-minute N, --rate-start-burst N (default 20, 10), --rate-upgrade-per-minute N,\n"
         "  --rate-upgrade-burst N (default 60, 30)   per-address rate limits on /start and WebSocket upgrades\n"
         "                          (429 with Retry-After; 0 = off; every address, loopback included)\n"
         "  --max-connections-per-address N (default 64), --max-connections N (default: from the descriptor limit)\n"
         "  --max-unspent-sessions-per-address N   live sessions one address started that no participant has\n"
         "                          seen yet (default 3)\n"
         "  --ws-ping-interval-s S, --ws-pong-timeout-s S   WebSocket keep-alive (default 20, 20; 0 = off)\n"
         "  --trusted-proxies A,B   front ends whose X-Forwarded-For names the participant (addresses or CIDR)\n"
         "  --on-data-incomplete continue|end   when a session's data cannot be written (default continue)\n"
         "  --after-session-command ARG   one argument of the command that copies each ended session's folder off\n"
         "                          this host (repeat; no shell; {folder} {folder_name} {uid} {host} {session_id})\n"
         "  --after-session-retries N (default 5), --after-session-timeout-s S (default 600)   its tries\n"
         "  --cluster-peers ID=ADDR:PORT,...   every host's uid registry, this one included (several hosts:\n"
         "                          a uid gets one session in the whole cluster; needs --host-id; the same\n"
         "                          entries on every host, an odd number of them)\n"
         "  --cluster-secret-file F the hosts' shared registry secret, 16+ bytes (mode 0600)\n"
         "  --registry-port N       this host's registry port (default: its cluster-peers entry's)\n"
         "  --registry-bind ADDR    the registry's numeric IPv4 address (default: listen-address)\n"
         "  --ros-connect URL       ws:// or wss:// rosbridge_server of a lab: each session of a scenario with a\n"
         "                          robot dials out to it (the ros: section of the file; default: no ROS)\n"
         "  --ros-token-file F, --ros-ca-file F   a Bearer token and extra CA certificates for that dial-out\n"
         "  --ros-namespace NS      each session's topics under NS/s_<id> (default /rfbsim)\n"
         "  --ros-robot-control builtin|external  who drives the robot where a link does not say (default builtin)\n"
         "  --ros-cmd-vel-type twist|twist_stamped  the type of the lab's /cmd_vel (default twist)\n"
         "  --x11-geometry WxH      session_kind x11: the display's size (default 1280x720; the x11: section)\n"
         "  --x11-depth D           its bits per pixel: 16 or 24 (default)\n"
         "  --x11-xvnc PATH         TigerVNC's Xvnc (default /usr/bin/Xvnc)\n"
         "  --sign QUERY            print QUERY with its link signature (needs a link secret) and exit\n";
}

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
    const auto setting = settings().find(key);
    if (setting == settings().end()) {
      outcome.error = where + "unknown setting";
      return false;
    }
    std::vector<std::string> values;
    if (setting->second.list && node.IsSequence()) {
      for (const auto& element : node) {
        if (!element.IsScalar()) {
          outcome.error = where + "expected a list of plain values";
          return false;
        }
        values.push_back(element.Scalar());
      }
    } else if (node.IsScalar()) {
      values.push_back(node.Scalar());
      if (setting->second.list) values = split_commas(node.Scalar());
    } else {
      outcome.error = where + (setting->second.list ? "expected a list" : "expected a single value");
      return false;
    }
    if (!setting->second.list && values.empty()) values.emplace_back();
    const std::string problem = setting->second.apply(outcome.config, values);
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
    static const std::map<std::string, std::vector<std::string>> kSections = {
        {"ros", {"connect", "token_file", "ca_file", "namespace", "robot_control", "cmd_vel_type"}},
        {"x11", {"geometry", "depth", "xvnc"}}};
    for (const auto& [section, keys] : kSections) {
      if (key.rfind(section + "_", 0) == 0) {
        outcome.error = line + key + ": unknown setting (write it as " + key.substr(section.size() + 1) + ": under " +
                        section + ":)";
        return outcome;
      }
    }
    const auto section = kSections.find(key);
    if (section == kSections.end()) {
      if (!apply(key, key, item.first, item.second)) return outcome;
      continue;
    }
    std::string known;
    for (const std::string& name : section->second) known += (known.empty() ? "" : ", ") + name;
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
      if (std::find(section->second.begin(), section->second.end(), name) == section->second.end()) {
        outcome.error = at + key + "." + name + ": unknown setting (known: " + known + ")";
        return outcome;
      }
      if (!apply(key + "_" + name, key + "." + name, sub.first, sub.second)) return outcome;
    }
  }
  return outcome;
}

ConfigOutcome parse_manager_args(const std::vector<std::string>& args,
                                 const std::vector<std::pair<std::string, std::string>>& environment) {
  ConfigOutcome outcome;
  // The config file first, wherever --config stands, so that flags always win over it.
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] != "--config") continue;
    if (i + 1 >= args.size()) {
      outcome.error = "--config needs a file";
      return outcome;
    }
    outcome = load_config_file(args[i + 1], outcome.config);
    if (!outcome.error.empty()) return outcome;
  }
  bool session_args_from_flags = false;
  bool copy_command_from_flags = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& flag = args[i];
    if (flag == "--help" || flag == "-h") {
      outcome.help = true;
      return outcome;
    }
    if (flag.rfind("--", 0) != 0) {
      outcome.error = "unexpected argument '" + flag + "'";
      return outcome;
    }
    if (i + 1 >= args.size()) {
      outcome.error = flag + " needs a value";
      return outcome;
    }
    const std::string& value = args[++i];
    if (flag == "--config") continue;
    if (flag == "--sign") {
      outcome.sign_query = value;
      continue;
    }
    if (flag == "--session-arg") {
      // Repeated: the flags' list replaces the file's as a whole.
      if (!session_args_from_flags) outcome.config.session_args.clear();
      session_args_from_flags = true;
      outcome.config.session_args.push_back(value);
      continue;
    }
    if (flag == "--after-session-command") {
      // Repeated, one argument each (a path or an rclone flag may hold a comma); the flags' list replaces the
      // file's as a whole, and is checked once it is complete (below).
      if (!copy_command_from_flags) outcome.config.after_session_command.clear();
      copy_command_from_flags = true;
      outcome.config.after_session_command.push_back(value);
      continue;
    }
    const auto setting = settings().find(flag_to_key(flag));
    if (setting == settings().end() || flag_to_key(flag) == "session_args") {
      outcome.error = "unknown option '" + flag + "'";
      return outcome;
    }
    const std::vector<std::string> values =
        setting->second.list ? split_commas(value) : std::vector<std::string>{value};
    const std::string problem = setting->second.apply(outcome.config, values);
    if (!problem.empty()) {
      // Secrets are never echoed: error messages end up in logs and terminals.
      const bool secret = setting->first == "admin_token" || setting->first == "link_secret";
      outcome.error = flag + (secret ? "" : " '" + value + "'") + ": " + problem;
      return outcome;
    }
  }
  // Secrets from the environment (e.g. a systemd EnvironmentFile) keep them out of `ps`.
  for (const auto& [name, value] : environment) {
    const char* key = name == "RFBSIM_ADMIN_TOKEN" ? "admin_token" : name == "RFBSIM_LINK_SECRET" ? "link_secret" : nullptr;
    if (key == nullptr) continue;
    std::string& field = name == "RFBSIM_ADMIN_TOKEN" ? outcome.config.admin_token : outcome.config.link_secret;
    if (!field.empty()) continue;
    const std::string problem = settings().at(key).apply(outcome.config, {value});
    if (!problem.empty()) {
      outcome.error = name + ": " + problem;
      return outcome;
    }
  }
  // In a cluster each host owns "/<host_id>" of the balancer's URL space unless told otherwise (the balancer
  // routes /<id>/... to host <id>, and a registry answer sends a participant to /<id>/start).
  ManagerConfig& config = outcome.config;
  if (config.path_prefix.empty() && !config.cluster_peers.empty() && is_path_prefix("/" + config.host_id)) {
    config.path_prefix = "/" + config.host_id;
  }
  finish_config(config);
  if (outcome.error.empty()) outcome.error = validate_config(outcome.config);
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
