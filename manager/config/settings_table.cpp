// SPDX-License-Identifier: GPL-2.0-or-later
#include "config/settings_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>

#include "admission/start_request.hpp"
#include "config/ros_settings.hpp"
#include "config/setting_kinds.hpp"
#include "contract/validators.hpp"
#include "http/client_address.hpp"
#include "http/routes.hpp"
#include "cluster/uid_registry.hpp"
#include "rfbsim/log.hpp"
#include "sessions/copy_command.hpp"

namespace rfbsim::manager::config_table {

namespace {

// limits.cpu_slack_s's bound: a day of CPU beyond the session's share (a guard against typos, not a task bound).
constexpr long long kMaxCpuSlackS = 24LL * 3600;

// The largest address space and descriptor limits a session may be given (far past any machine's).
constexpr std::uint64_t kMaxAddressSpaceMb = 1ULL << 30;
constexpr std::uint64_t kMaxOpenFiles = 1ULL << 20;

using Values = std::vector<std::string>;
using Shown = std::optional<Values>;

Setting row(std::string key, ValueKind kind, std::string help, std::string default_note = {}) {
  return {std::move(key), std::move(kind), std::move(help), std::move(default_note), false};
}

Setting secret_row(std::string key, ValueKind kind, std::string help) {
  Setting setting = row(std::move(key), std::move(kind), std::move(help));
  setting.secret = true;
  return setting;
}

// The numbers --print-config writes: the shortest text that reads back as the same double.
std::string shortest(double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

std::vector<Setting> build_table() {
  // Kinds of value only one setting takes are written out here.
  ValueKind max_duration = seconds(&ManagerConfig::max_duration, 1);
  max_duration.apply = [apply = max_duration.apply](ManagerConfig& c, const Values& v) {
    c.max_duration_set = true;  // the researcher's own limit: fit_max_duration keeps it
    return apply(c, v);
  };
  // Unset, it is fitted to the scenarios' tasks at start-up: written as a number it would no longer be.
  max_duration.show = [show = max_duration.show](const ManagerConfig& c) -> Shown {
    return c.max_duration_set ? show(c) : std::nullopt;
  };

  ValueKind scenarios = checked_list(&ManagerConfig::scenarios, "A,B", [](const std::string& entry) -> std::string {
    if (is_identifier(entry.substr(0, entry.find('=')))) return "";
    return "'" + entry + "' is not a scenario name (letters, digits, - and _, at most 64), optionally =FILE";
  });
  scenarios.apply = [apply = scenarios.apply](ManagerConfig& c, const Values& v) -> std::string {
    if (v.empty()) return "list at least one scenario";
    if (std::string problem = apply(c, v); !problem.empty()) return problem;
    c.scenarios_set = true;
    return "";
  };
  // session_kind rfb and x11 offer none unless told (finish_config): an empty list is not a value to write.
  scenarios.show = [](const ManagerConfig& c) -> Shown {
    return c.scenarios.empty() ? std::nullopt : Shown(c.scenarios);
  };

  ValueKind address_space = limit_count(&ProcessLimits::address_space_mb, kMaxAddressSpaceMb, "MB", "MiB");
  address_space.apply = [apply = address_space.apply](ManagerConfig& c, const Values& v) -> std::string {
    if (std::string problem = apply(c, v); !problem.empty()) return problem;
    c.limits.address_space_set = true;  // kept for every session kind
    return "";
  };
  address_space.show = [show = address_space.show](const ManagerConfig& c) -> Shown {
    return c.limits.address_space_set ? show(c) : std::nullopt;
  };

  const ValueKind cpu_factor{
      "F", "0..256, 0 = no limit", false,
      [](ManagerConfig& c, const Values& v) -> std::string {
        double factor = 0;
        const char* end = v.front().data() + v.front().size();
        const auto [ptr, ec] = std::from_chars(v.front().data(), end, factor);
        if (v.front().empty() || ec != std::errc() || ptr != end || !std::isfinite(factor) || factor < 0 ||
            factor > 256) {
          return "expected cores per session 0..256, 0 = no CPU limit";
        }
        c.limits.cpu_time_factor = factor;
        return "";
      },
      [](const ManagerConfig& c) -> Shown { return Values{shortest(c.limits.cpu_time_factor)}; }};

  const ValueKind cpu_slack{
      "S", "0.." + std::to_string(kMaxCpuSlackS), false,
      [](ManagerConfig& c, const Values& v) -> std::string {
        long long value = 0;
        if (!parse_integer(v.front(), 0LL, kMaxCpuSlackS, value)) {
          return "expected whole seconds 0.." + std::to_string(kMaxCpuSlackS);
        }
        c.limits.cpu_slack = std::chrono::seconds(value);
        return "";
      },
      [](const ManagerConfig& c) -> Shown { return Values{std::to_string(c.limits.cpu_slack.count())}; }};

  const ValueKind session_args{"ARG", "", true,
                               [](ManagerConfig& c, const Values& v) -> std::string {
                                 c.session_args = v;
                                 return "";
                               },
                               [](const ManagerConfig& c) -> Shown { return c.session_args; }};

  const ValueKind after_session_command{"ARG", "", true,
                                        [](ManagerConfig& c, const Values& v) -> std::string {
                                          if (std::string problem = copy_command_problem(v); !problem.empty()) {
                                            return problem;
                                          }
                                          c.after_session_command = v;
                                          return "";
                                        },
                                        [](const ManagerConfig& c) -> Shown { return c.after_session_command; }};

  const ValueKind x11_geometry{
      "WxH", "64..8192 each", false,
      [](ManagerConfig& c, const Values& v) -> std::string {
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
      },
      [](const ManagerConfig& c) -> Shown {
        return Values{std::to_string(c.x11.width) + "x" + std::to_string(c.x11.height)};
      }};

  const ValueKind x11_depth{"D", "16 or 24", false,
                            [](ManagerConfig& c, const Values& v) -> std::string {
                              int depth = 0;
                              if (!parse_integer(v.front(), 16, 24, depth) || (depth != 16 && depth != 24)) {
                                return "expected 16 or 24";
                              }
                              c.x11.depth = depth;
                              return "";
                            },
                            [](const ManagerConfig& c) -> Shown { return Values{std::to_string(c.x11.depth)}; }};

  const ValueKind x11_xvnc{"PATH", "", false,
                           [](ManagerConfig& c, const Values& v) -> std::string {
                             if (v.front().empty() || v.front().front() != '/') {
                               return "expected the absolute path of TigerVNC's Xvnc";
                             }
                             c.x11.xvnc = v.front();
                             return "";
                           },
                           [](const ManagerConfig& c) -> Shown { return Values{c.x11.xvnc}; }};

  // 0 stands for "the port of this host's cluster_peers entry", which the file does not write.
  ValueKind registry_port = integer(&ManagerConfig::registry_port, 1, 65535);
  registry_port.show = [show = registry_port.show](const ManagerConfig& c) -> Shown {
    return c.registry_port == 0 ? std::nullopt : show(c);
  };

  const auto origin_problem = [](const std::string& origin) -> std::string {
    if (contract::is_browser_origin(origin)) return "";
    return "'" + origin + "' is not an origin such as https://survey.example.org (lower case, no path)";
  };

  return {
      row("listen_address", ipv4_address(&ManagerConfig::listen_address),
          "numeric IPv4 address to listen on; `0.0.0.0` for every interface"),
      row("port", integer(&ManagerConfig::port, 0, 65535), "the one public port (0 = any free port, printed at start)"),
      row("tls_certificate", text(&ManagerConfig::tls_certificate, "PEM"),
          "PEM certificate chain; with `tls_private_key` the port speaks HTTPS and WSS only"),
      row("tls_private_key", text(&ManagerConfig::tls_private_key, "PEM"), "PEM private key of `tls_certificate`"),
      row("session_command", text(&ManagerConfig::session_command, "PROGRAM"),
          "the program started per session; `sim_rfb` means the one built or installed"),
      row("session_kind",
          enum_choice(&ManagerConfig::session_kind, {{"sim_rfb", SessionKind::kSimRfb},
                                                     {"rfb", SessionKind::kRfb},
                                                     {"x11", SessionKind::kX11}}),
          "`sim_rfb`; `rfb` for any program that serves raw RFB on the port it is told as `{port}` (one linking "
          "librfbsim); `x11` for any unmodified X11 program, each session on its own Xvnc display "
          "(docs/other-simulators.md)"),
      row("session_args", session_args,
          "extra arguments for the session program (one `--session-arg ARG` flag each); for `rfb` and `x11`, the "
          "program's whole argument list with placeholders"),
      row("codec", choice(&ManagerConfig::codec, {"auto", "jpeg", "h264"}),
          "sim_rfb's picture encoding: `auto` (Tight JPEG, H.264 for a browser that offers it once its link needs "
          "it), `jpeg`, or `h264` (see \"Picture encoding\")"),
      row("session_socket", choice(&ManagerConfig::session_socket, {"unix", "tcp"}),
          "how the relay reaches sim_rfb: a private unix socket, or `tcp` (a loopback port any local user could "
          "open)"),
      row("log_level", choice(&ManagerConfig::log_level, Values(std::begin(rfbsim::log::kLevelNames), std::end(rfbsim::log::kLevelNames))),
          "the manager's log (lines a client can cause, such as a refused connection, are rate-limited: past 5 of "
          "a kind in 10 s one \"N more like this suppressed\" line says how many were left out)"),
      row("max_sessions", integer(&ManagerConfig::max_sessions, 1, 10000),
          "live sessions at once; the next participant is told to wait"),
      row("max_duration_s", max_duration,
          "a session ends this long after `/start` (SEAN-EP: 5 min); unset, it grows to what the offered "
          "scenarios' tasks need (see \"Scenarios and session length\")",
          "`300`, or what the tasks need"),
      row("idle_timeout_s", seconds(&ManagerConfig::idle_timeout, 1),
          "a session ends after this long with no browser connected"),
      row("first_connect_timeout_s", seconds(&ManagerConfig::first_connect_timeout, 1),
          "a session no browser ever connected to ends this long after `/start` (a link preview's session must not "
          "hold a slot for the whole idle timeout)"),
      row("start_timeout_s", seconds(&ManagerConfig::start_timeout, 1), "a session not ready by then has failed"),
      row("stop_grace_s", seconds(&ManagerConfig::stop_grace, 0), "SIGTERM, then SIGKILL this long after"),
      row("data_dir", text(&ManagerConfig::data_dir, "DIR"),
          "`sessions.db` (the index) and `sessions/<id>-<uid>/` per session"),
      row("scenarios", scenarios,
          "scenarios links may name, the first the default; an entry `NAME=FILE` serves your own scenario file as "
          "NAME (a relative FILE is taken from the manager's working directory); without any (the default of "
          "`rfb` and `x11`) links need only `uid` and `{scenario}` is empty",
          "`rfb`, `x11`: none"),
      row("frame_origins", checked_list(&ManagerConfig::frame_origins, "O1,O2", origin_problem),
          "origins allowed to frame the page and open its WebSocket, e.g. `https://yourschool.qualtrics.com`"),
      secret_row("admin_token", secret(&ManagerConfig::admin_token),
                 "turns on `/admin` and `/api/sessions` (or `RFBSIM_ADMIN_TOKEN`)"),
      secret_row("link_secret", secret(&ManagerConfig::link_secret),
                 "`/start` links must carry a valid `sig` (or `RFBSIM_LINK_SECRET`)"),
      row("require_link_expiry", boolean(&ManagerConfig::require_link_expiry),
          "with `link_secret`: links must carry a signed `exp` (a Unix time, seconds), and expire then"),
      row("allow_repeat", boolean(&ManagerConfig::allow_repeat), "a uid whose session ended may start another"),
      row("allow_camera_param", boolean(&ManagerConfig::allow_camera_param),
          "links may choose the participant's view with `camera`; off, such a link is refused (400)"),
      row("yoke_max_viewers", integer(&ManagerConfig::yoke_max_viewers, 1, 1000),
          "the video condition (`condition=video` links): how many watchers one interactive session may have "
          "(with `by_participant`, also how many watchers one walker may be paired with)"),
      row("yoke_policy", choice(&ManagerConfig::yoke_policy, {"earliest_ended", "by_participant"}),
          "how a watcher's source session is chosen: `earliest_ended` (per link, the earliest-ended spent "
          "session of the link's scenario with room) or `by_participant` (every link of a watcher shows the same "
          "walker, paired at the watcher's first link; see docs/study-guide.md)"),
      row("host_id",
          checked_text(&ManagerConfig::host_id, "ID", "",
                       [](const std::string& value) -> std::string {
                         return is_identifier(value) ? "" : "expected letters, digits, - and _ (at most 64)";
                       }),
          "this host's name, recorded with every session in the index", "the host name"),
      row("web_root", text(&ManagerConfig::web_root, "DIR"), "the participant page", "built or installed"),
      row("public_url",
          checked_text(&ManagerConfig::public_url, "ORIGIN", "",
                       [](const std::string& value) -> std::string {
                         if (contract::is_browser_origin(value)) return "";
                         return "expected an origin such as https://h1.study.example.org (no path)";
                       }),
          "this host's public origin; `/start` redirects there (see \"Several hosts\")"),
      row("path_prefix",
          checked_text(&ManagerConfig::path_prefix, "/ID", "",
                       [](const std::string& value) -> std::string {
                         return is_path_prefix(value) ? "" : "expected / and 1-32 of a-z, 0-9 and - (e.g. /h2)";
                       }),
          "this host's part of a balancer's URL space, `/` and 1-32 of `a-z 0-9 -`: pages, sockets and the admin "
          "API answer under it (see \"Path prefix, drain and agent-check\")",
          "none (`/HOST_ID` with `cluster_peers`)"),
      row("agent_port", integer(&ManagerConfig::agent_port, 0, 65535),
          "HAProxy agent-check port: each connection reads `up ready NN%` or `drain` (0 = off)"),
      row("agent_bind", ipv4_address(&ManagerConfig::agent_bind), "the agent port's numeric IPv4 address",
          "`listen_address`"),
      row("limit_address_space_mb", address_space,
          "RLIMIT_AS per session process; an X11 program such as a Unity build reserves far more address "
          "space than it uses",
          "`8192` (`x11`: `65536`)"),
      row("limit_open_files", limit_count(&ProcessLimits::open_files, kMaxOpenFiles, "N", "a count"),
          "RLIMIT_NOFILE per session"),
      row("limit_cpu_time_factor", cpu_factor,
          "RLIMIT_CPU = max_duration × this + slack + grace: about how many cores a session may use on "
          "average"),
      row("limit_cpu_slack_s", cpu_slack, "added to the CPU limit"),
      row("rate_start_per_minute", abuse_count(&AbuseLimits::start_per_minute),
          "`/start` requests per client address per minute, sustained (429 + `Retry-After` beyond)"),
      row("rate_start_burst", abuse_count(&AbuseLimits::start_burst), "`/start` requests per client address at once"),
      row("rate_upgrade_per_minute", abuse_count(&AbuseLimits::upgrade_per_minute),
          "WebSocket upgrades per client address per minute, sustained (reconnects)"),
      row("rate_upgrade_burst", abuse_count(&AbuseLimits::upgrade_burst),
          "WebSocket upgrades per client address at once"),
      row("max_connections_per_address", abuse_count(&AbuseLimits::connections_per_address),
          "open connections per client address; more are closed at accept"),
      row("max_connections", abuse_count(&AbuseLimits::connections_total),
          "open connections in all (0 = the descriptor limit minus what sessions need)"),
      row("max_unspent_sessions_per_address", abuse_count(&AbuseLimits::unspent_sessions_per_address),
          "live sessions one address started that no participant has seen yet"),
      row("ws_ping_interval_s", abuse_seconds(&AbuseLimits::ws_ping_interval), "a ping to every WebSocket this often"),
      row("ws_pong_timeout_s", abuse_seconds(&AbuseLimits::ws_pong_timeout),
          "a WebSocket whose pong is this late is closed"),
      row("trusted_proxies",
          checked_list(&ManagerConfig::trusted_proxies, "A,B",
                       [](const std::string& entry) -> std::string {
                         if (parse_address_range(entry)) return "";
                         return "'" + entry + "' is not an address or CIDR range such as 10.0.0.0/8";
                       }),
          "front ends whose `X-Forwarded-For` names the participant (addresses or CIDR ranges)"),
      row("on_data_incomplete",
          enum_choice(&ManagerConfig::on_data_incomplete,
                      {{"continue", DataFailurePolicy::kContinue}, {"end", DataFailurePolicy::kEnd}}),
          "when a session's data cannot be written (a full disk): `continue` (the participant carries on; the "
          "index marks the session `data_incomplete`) or `end` (the session ends and the page says so)"),
      row("after_session_command", after_session_command,
          "the command that copies each ended session's folder off this host: an argument list, no shell, with "
          "`{folder}` `{folder_name}` `{uid}` `{host}` `{session_id}` (one `--after-session-command ARG` flag per "
          "argument; see \"Copying each session off the host\")"),
      row("after_session_retries", integer(&ManagerConfig::after_session_retries, 0, 100),
          "tries after a failed first one, 5 s apart and then doubling up to 5 min"),
      row("after_session_timeout_s", seconds(&ManagerConfig::after_session_timeout, 1),
          "one try's limit; then SIGTERM to the command's process group, SIGKILL after `stop_grace_s`"),
      row("cluster_peers", cluster_peers(),
          "every host's uid registry as `ID=ADDRESS:PORT`, this one included: a uid gets one session in the whole cluster (needs "
          "`host_id`; the same entries on every host, an odd number of them; see \"Several hosts\")"),
      row("cluster_secret_file", text(&ManagerConfig::cluster_secret_file, "FILE"),
          "the hosts' shared registry secret, 16 bytes or more (mode 0600)"),
      row("registry_port", registry_port, "this host's registry port", "its `cluster_peers` entry's"),
      row("registry_bind", ipv4_address(&ManagerConfig::registry_bind), "the registry's numeric IPv4 address",
          "`listen_address`"),
      row("ros_connect", ros_text(&RosSettings::connect, "URL", rosbridge_url_problem),
          "a lab's rosbridge_server, `ws://` or `wss://`: each session of a scenario with a robot dials out to it "
          "(see \"ROS\")",
          "none: no ROS"),
      row("ros_token_file", ros_file(&RosSettings::token_file, token_file_problem),
          "a Bearer token for that dial-out (one line)"),
      row("ros_ca_file", ros_file(&RosSettings::ca_file, ca_file_problem),
          "extra PEM CA certificates for a `wss://` dial-out", "the system's only"),
      row("ros_namespace",
          ros_text(&RosSettings::ros_namespace, "NS",
                   [](const std::string& value) -> std::string {
                     if (is_ros_name(value)) return "";
                     return "expected a ROS name such as /rfbsim: '/', then segments of letters, digits and '_' that "
                            "start with a letter, joined by '/', no '/' at the end";
                   }),
          "each session's topics go under `<namespace>/s_<id>`"),
      row("ros_robot_control", ros_choice(&RosSettings::robot_control, {"builtin", "external"}),
          "who drives the robot where a link does not say", "the scenario's `robot.control`"),
      row("ros_cmd_vel_type", ros_choice(&RosSettings::cmd_vel_type, {"twist", "twist_stamped"}),
          "the type of the lab's `/cmd_vel`"),
      row("x11_geometry", x11_geometry, "`x11` only: the display's, and so the picture's, size"),
      row("x11_depth", x11_depth, "`x11` only: the display's bits per pixel"),
      row("x11_xvnc", x11_xvnc, "`x11` only: TigerVNC's Xvnc (Debian: tigervnc-standalone-server)"),
  };
}

}  // namespace

const std::vector<Setting>& settings() {
  static const std::vector<Setting> table = build_table();
  return table;
}

const Setting* find_setting(const std::string& key) {
  for (const Setting& setting : settings()) {
    if (setting.key == key) return &setting;
  }
  return nullptr;
}

std::string flag_of(const std::string& key) {
  std::string flag = "--" + key;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string section_of(const std::string& key) {
  for (const std::string& section : kSections) {
    if (key.rfind(section + "_", 0) == 0) return section;
  }
  return {};
}

std::string file_name_of(const std::string& key) {
  const std::string section = section_of(key);
  return section.empty() ? key : section + "." + key.substr(section.size() + 1);
}

std::string plain_text(std::string markdown) {
  markdown.erase(std::remove(markdown.begin(), markdown.end(), '`'), markdown.end());
  return markdown;
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
