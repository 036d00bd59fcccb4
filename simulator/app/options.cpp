// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's command-line parser.
#include "app/options.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <functional>
#include <map>

#include "contract/validators.hpp"

namespace rfbsim::sim {

namespace {

template <typename T>
bool parse_number(const std::string& text, T low, T high, T& out) {
  T value{};
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || value < low || value > high) return false;
  out = value;
  return true;
}

// The values sim_manager also checks before it passes them here: one rule each, in the contract
// (contract/validators.hpp), so that the two programs cannot disagree.
using contract::is_identifier;      // participant ids and completion codes
using contract::looks_like_origin;  // --allow-origin's shape; librfbsim checks the host and port when it starts

// A ROS graph name used as a topic prefix, up to the contract's kMaxRosName (room for sim_manager's root and
// its "/s_<id>_<host>").
bool is_ros_namespace(const std::string& text) { return contract::is_ros_name(text); }

// ws://host[:port][/path] or wss://...: the shape only (the client parses it fully when it starts). No user info
// and no query: credentials go in --rosbridge-token-file, never in a URL that logs, session.json and ps show.
bool looks_like_websocket_url(const std::string& text) { return contract::websocket_url_problem(text).empty(); }

}  // namespace

std::string sim_usage() {
  return "usage: sim_rfb [--port N] [--bind ADDR] [--width W] [--height H] [--fps F] [--seed S]\n"
         "               [--scenario NAME|PATH] [--avatar-start P] [--avatar-goal P] [--robot-start P]\n"
         "               [--robot-goal P] [--crowd N]\n"
         "               [--quality Q] [--codec auto|jpeg|h264] [--max-clients N] [--web-root DIR]\n"
         "               [--egl auto|device|surfaceless]\n"
         "               [--debug-overlay] [--rfb-only] [--proxy-protocol] [--ready-fd N]\n"
         "               [--allow-origin ORIGIN]... [--unix-socket PATH]\n"
         "               [--data-dir DIR] [--uid ID] [--code-success C] [--code-timeout C]\n"
         "               [--time-limit S] [--end-grace S] [--trajectory-hz N] [--no-mcap] [--robot-control C]\n"
         "               [--rosbridge-port N] [--rosbridge-bind ADDR] [--rosbridge-connect URL]\n"
         "               [--rosbridge-token-file F] [--rosbridge-ca F] [--ros-namespace NS]\n"
         "               [--cmd-vel-type twist|twist_stamped]\n"
         "  --port N         TCP port for the page, WebSocket and RFB (default 5901; 0 = any free port)\n"
         "  --bind ADDR      numeric address to listen on (default 127.0.0.1)\n"
         "  --width W        frame width in pixels, 160..3840 (default 1280)\n"
         "  --height H       frame height in pixels, 120..2160 (default 720)\n"
         "  --fps F          frames per second while someone watches, 1..120 (default 30)\n"
         "  --seed S         random seed (default: the scenario's)\n"
         "  --scenario S     scenario name (warehouse, lab) or YAML file (default: a small test room)\n"
         "  --avatar-start P, --avatar-goal P, --robot-start P, --robot-goal P\n"
         "                   a spawn point's name or x,y,yaw in metres and radians\n"
         "  --crowd N        number of pedestrians, 0..500 (default: the scenario's)\n"
         "  --quality Q      JPEG quality 1..100 (default 80)\n"
         "  --codec C        picture encoding: auto (default: Tight JPEG, H.264 for a client that offers it once\n"
         "                   its link cannot carry the frame rate), jpeg (Tight JPEG always) or h264 (H.264 for\n"
         "                   every client that offers it, such as noVNC 1.6+ over https)\n"
         "  --max-clients N  viewers at once, 1..64 (default 4)\n"
         "  --web-root DIR   directory holding the participant page (default: the built page)\n"
         "  --egl P          EGL platform (default auto: GPU device, else Mesa surfaceless)\n"
         "  --debug-overlay  draw the robot's global path, local trajectory, goal, pose estimate and social\n"
         "                   cost on the floor (for developers; participants should not see it)\n"
         "  --rfb-only       serve RFB only (raw and over WebSocket): no page, no /status.json; a raw RFB\n"
         "                   client is then served after 0.1 s instead of 0.5 s (at once behind --proxy-protocol)\n"
         "  --proxy-protocol each connection begins with a PROXY protocol v1 line naming the real client,\n"
         "                   as sim_manager's relay sends it (for a trusted relay only: never on a port\n"
         "                   that others reach)\n"
         "  --allow-origin O also accept WebSocket upgrades from pages at origin O (scheme://host[:port], or *\n"
         "                   for any page); repeatable. Without it only this server's own page and loopback\n"
         "                   pages (http(s)://127.0.0.1, localhost, [::1]) may open the stream; others get 403\n"
         "  --unix-socket P  listen on unix socket P (mode 0600: only this user may connect) instead of TCP;\n"
         "                   replaces --port and --bind (giving either is an error); a stale socket there is\n"
         "                   replaced, the file is removed at exit\n"
         "  --ready-fd N     once listening, write 'ready PORT' ('ready unix PATH' with --unix-socket) and a\n"
         "                   newline to file descriptor N (3 or above, e.g. a pipe from the parent) and\n"
         "                   keep it open: later lines report the\n"
         "                   viewers' stream about once a second ('stream codec=tight rtt_ms=12.5 fps=29.8\n"
         "                   quality=80 clients=1') and the task's outcome ('outcome completed' or 'outcome\n"
         "                   timeout'); exit 1 if the ready line cannot be written\n"
         "  --data-dir DIR   record the session there: session.json, trajectories.csv, events.jsonl\n"
         "                   (docs/data.md); without it nothing is recorded\n"
         "  --uid ID         participant id recorded in session.json (letters, digits, - and _)\n"
         "  --code-success C, --code-timeout C\n"
         "                   completion codes shown when the task is done or the time is up (1..64 of\n"
         "                   letters, digits, - and _; SEAN-EP's t1 and t2)\n"
         "  --time-limit S   the task's time limit in seconds, 1..86400 (default: the scenario's)\n"
         "  --end-grace S    seconds the outcome and the code stay on screen before the session ends, 0..3600\n"
         "                   (default: the scenario's end_grace)\n"
         "  --trajectory-hz N  trajectory rows per second, a divisor of the tick rate 60 (default 10)\n"
         "  --no-mcap        with --data-dir, do not write session.mcap (the ROS 2 bag, docs/ros.md)\n"
         "  --robot-control C  builtin (the robot's own navigation stack) or external (/cmd_vel over rosbridge\n"
         "                   drives it; it stops 0.5 s after the last command) (default: the scenario's)\n"
         "  --rosbridge-port N  serve the ROS topics live over rosbridge v2 (JSON over WebSocket at /) on\n"
         "                   port N (0 = any free port). Unauthenticated: keep it on loopback\n"
         "  --rosbridge-bind ADDR  numeric address for --rosbridge-port (default 127.0.0.1)\n"
         "  --rosbridge-connect URL  dial out to a lab's rosbridge_server (ws:// or wss://) and publish there,\n"
         "                   taking /cmd_vel from it; reconnects by itself\n"
         "  --rosbridge-token-file F  send F's first line as 'Authorization: Bearer' when dialling out\n"
         "  --rosbridge-ca F  extra CA certificates (PEM) to trust for wss://\n"
         "  --ros-namespace NS  put every topic under NS (e.g. /rfbsim/s1): /rfbsim/s1/scan\n"
         "  --cmd-vel-type T twist (geometry_msgs/msg/Twist, the default) or twist_stamped: the type\n"
         "                   --rosbridge-connect subscribes to the lab's /cmd_vel with (--rosbridge-port takes both)\n";
}

ParseOutcome parse_sim_options(const std::vector<std::string>& args) {
  ParseOutcome outcome;
  SimOptions& o = outcome.options;
  // Each option that takes a value: its parser returns false when the value is bad.
  const std::map<std::string, std::function<bool(const std::string&)>> with_value = {
      {"--port", [&](const std::string& v) { return parse_number(v, 0, 65535, o.port); }},
      {"--bind", [&](const std::string& v) { o.bind = v; return !v.empty(); }},
      {"--width", [&](const std::string& v) { return parse_number(v, 160, 3840, o.width); }},
      {"--height", [&](const std::string& v) { return parse_number(v, 120, 2160, o.height); }},
      {"--fps", [&](const std::string& v) { return parse_number(v, 1, 120, o.fps); }},
      {"--seed", [&](const std::string& v) {
         std::uint64_t seed = 0;
         if (!parse_number<std::uint64_t>(v, 0, UINT64_MAX, seed)) return false;
         o.seed = seed;
         return true;
       }},
      {"--scenario", [&](const std::string& v) { o.scenario = v; return !v.empty(); }},
      {"--avatar-start", [&](const std::string& v) { o.avatar_start = v; return !v.empty(); }},
      {"--avatar-goal", [&](const std::string& v) { o.avatar_goal = v; return !v.empty(); }},
      {"--robot-start", [&](const std::string& v) { o.robot_start = v; return !v.empty(); }},
      {"--robot-goal", [&](const std::string& v) { o.robot_goal = v; return !v.empty(); }},
      {"--crowd", [&](const std::string& v) {
         int count = 0;
         if (!parse_number(v, 0, 500, count)) return false;
         o.crowd = count;
         return true;
       }},
      {"--quality", [&](const std::string& v) { return parse_number(v, 1, 100, o.jpeg_quality); }},
      {"--codec", [&](const std::string& v) {
         o.codec = v;
         return v == "auto" || v == "jpeg" || v == "h264";
       }},
      {"--max-clients", [&](const std::string& v) { return parse_number(v, 1, 64, o.max_clients); }},
      {"--web-root", [&](const std::string& v) { o.web_root = v; return !v.empty(); }},
      {"--allow-origin", [&](const std::string& v) {
         o.allowed_origins.push_back(v);
         return looks_like_origin(v);
       }},
      {"--unix-socket", [&](const std::string& v) {
         // The path goes into the one-line ready message: no line breaks or other control characters.
         o.unix_socket = v;
         return !v.empty() && std::none_of(v.begin(), v.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
       }},
      {"--ready-fd", [&](const std::string& v) {
         // 0, 1 and 2 are stdin, stdout and stderr: writing the ready line there is surely a mistake.
         int fd = 0;
         if (!parse_number(v, 3, INT_MAX, fd)) return false;
         o.ready_fd = fd;
         return true;
       }},
      {"--data-dir", [&](const std::string& v) { o.data_dir = v; return !v.empty(); }},
      {"--uid", [&](const std::string& v) { o.uid = v; return is_identifier(v); }},
      {"--code-success", [&](const std::string& v) { o.code_success = v; return is_identifier(v); }},
      {"--code-timeout", [&](const std::string& v) { o.code_timeout = v; return is_identifier(v); }},
      {"--time-limit", [&](const std::string& v) {
         int seconds = 0;
         if (!parse_number(v, 1, 86400, seconds)) return false;
         o.time_limit = seconds;
         return true;
       }},
      {"--end-grace", [&](const std::string& v) {
         int seconds = 0;
         if (!parse_number(v, 0, 3600, seconds)) return false;
         o.end_grace = seconds;
         return true;
       }},
      {"--trajectory-hz", [&](const std::string& v) {
         return parse_number(v, 1, 60, o.trajectory_hz) && 60 % o.trajectory_hz == 0;
       }},
      {"--robot-control", [&](const std::string& v) {
         o.robot_control = v;
         return v == "builtin" || v == "external";
       }},
      {"--rosbridge-port", [&](const std::string& v) {
         int port = 0;
         if (!parse_number(v, 0, 65535, port)) return false;
         o.rosbridge_port = port;
         return true;
       }},
      {"--rosbridge-bind", [&](const std::string& v) { o.rosbridge_bind = v; return !v.empty(); }},
      {"--rosbridge-connect", [&](const std::string& v) { o.rosbridge_connect = v; return looks_like_websocket_url(v); }},
      {"--rosbridge-token-file", [&](const std::string& v) { o.rosbridge_token_file = v; return !v.empty(); }},
      {"--rosbridge-ca", [&](const std::string& v) { o.rosbridge_ca = v; return !v.empty(); }},
      {"--ros-namespace", [&](const std::string& v) { o.ros_namespace = v; return is_ros_namespace(v); }},
      {"--cmd-vel-type", [&](const std::string& v) {
         o.cmd_vel_type = v == "twist_stamped" ? "geometry_msgs/msg/TwistStamped" : "geometry_msgs/msg/Twist";
         return v == "twist" || v == "twist_stamped";
       }},
      {"--egl", [&](const std::string& v) {
         o.egl_platform = v;
         return v == "auto" || v == "device" || v == "surfaceless";
       }},
  };
  bool port_or_bind_given = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--port" || arg == "--bind") port_or_bind_given = true;
    if (arg == "--help" || arg == "-h") {
      o.help = true;
      continue;
    }
    if (arg == "--debug-overlay") {
      o.debug_overlay = true;
      continue;
    }
    if (arg == "--rfb-only") {
      o.rfb_only = true;
      continue;
    }
    if (arg == "--proxy-protocol") {
      o.proxy_protocol = true;
      continue;
    }
    if (arg == "--no-mcap") {
      o.mcap = false;
      continue;
    }
    auto option = with_value.find(arg);
    if (option == with_value.end()) {
      outcome.error = "unknown argument '" + arg + "'";
      return outcome;
    }
    if (i + 1 >= args.size()) {
      outcome.error = arg + " needs a value";
      return outcome;
    }
    const std::string& value = args[++i];
    if (!option->second(value)) {
      outcome.error = "bad value '" + value + "' for " + arg;
      // A choice among names is spelt out, so that a typo is fixed without reading the help.
      if (arg == "--codec") outcome.error += " (expected auto, jpeg or h264)";
      if (arg == "--allow-origin") outcome.error += " (expected scheme://host[:port] with http or https, or *)";
      if (arg == "--robot-control") outcome.error += " (expected builtin or external)";
      if (arg == "--cmd-vel-type") outcome.error += " (expected twist or twist_stamped)";
      if (arg == "--rosbridge-connect") {
        outcome.error += " (expected ws://host[:port][/path] or wss://..., without user info or query: a token goes in "
                         "--rosbridge-token-file)";
      }
      if (arg == "--ros-namespace") outcome.error += " (expected a ROS name such as /rfbsim/s1)";
      return outcome;
    }
  }
  // Without HTTP there is no page to serve: a web root given anyway shows a misunderstanding.
  if (o.rfb_only && !o.web_root.empty()) outcome.error = "--rfb-only serves no page; drop --web-root";
  if ((!o.rosbridge_token_file.empty() || !o.rosbridge_ca.empty()) && o.rosbridge_connect.empty()) {
    outcome.error = "--rosbridge-token-file and --rosbridge-ca are for --rosbridge-connect; give it too";
  }
  // Silently ignoring them would leave the caller believing a TCP port is open.
  if (!o.unix_socket.empty() && port_or_bind_given) {
    outcome.error = "--unix-socket replaces --port and --bind; drop them";
  }
  return outcome;
}

}  // namespace rfbsim::sim
