// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's command-line parser.
#include "app/options.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <functional>
#include <map>

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

// Participant ids and completion codes: safe in file names, logs and the HUD.
bool is_identifier(const std::string& text) {
  if (text.empty() || text.size() > 64) return false;
  for (const char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
    if (!ok) return false;
  }
  return true;
}

// The shape of an --allow-origin value; librfbsim checks the host and port when the server starts.
bool looks_like_origin(const std::string& text) {
  if (text == "*") return true;
  for (const std::string scheme : {"http://", "https://"}) {
    if (text.rfind(scheme, 0) == 0) {
      return text.size() > scheme.size() && text.find_first_of("/?#@ ", scheme.size()) == std::string::npos;
    }
  }
  return false;
}

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
         "               [--time-limit S] [--trajectory-hz N]\n"
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
         "  --trajectory-hz N  trajectory rows per second, a divisor of the tick rate 60 (default 10)\n";
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
      {"--trajectory-hz", [&](const std::string& v) {
         return parse_number(v, 1, 60, o.trajectory_hz) && 60 % o.trajectory_hz == 0;
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
      return outcome;
    }
  }
  // Without HTTP there is no page to serve: a web root given anyway shows a misunderstanding.
  if (o.rfb_only && !o.web_root.empty()) outcome.error = "--rfb-only serves no page; drop --web-root";
  // Silently ignoring them would leave the caller believing a TCP port is open.
  if (!o.unix_socket.empty() && port_or_bind_given) {
    outcome.error = "--unix-socket replaces --port and --bind; drop them";
  }
  return outcome;
}

}  // namespace rfbsim::sim
