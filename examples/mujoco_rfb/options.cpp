// SPDX-License-Identifier: GPL-2.0-or-later
// mujoco_rfb's command line: each flag takes its value from the next argument and is checked at once.
#include "options.hpp"

#include <charconv>
#include <functional>
#include <map>

namespace mujoco_rfb {

namespace {

// A whole decimal number in [low, high], or false.
bool parse_int(const std::string& text, int low, int high, int& out) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [at, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc{} || at != end || value < low || value > high) return false;
  out = value;
  return true;
}

}  // namespace

std::string usage() {
  return "usage: mujoco_rfb [--port N] [--bind ADDR] [--model FILE] [--width W] [--height H]\n"
         "                  [--web-root DIR | --rfb-only] [--help]\n"
         "  --port N       TCP port for RFB, WebSocket and the page (default 5902; 0 = any free port)\n"
         "  --bind ADDR    numeric address to listen on (default 127.0.0.1)\n"
         "  --model FILE   MJCF model (default: the bundled arm on a table)\n"
         "  --width W      frame width in pixels, 160..3840 (default 640)\n"
         "  --height H     frame height in pixels, 120..2160 (default 480)\n"
         "  --web-root DIR directory holding the page (default: the built or installed rfbsim page, if any)\n"
         "  --rfb-only     serve RFB only (raw and over WebSocket), no page: for sim_manager's sessions\n"
         "Keys: W/S or Up/Down move the shoulder, A/D or Left/Right turn the base, Q/E bend the elbow,\n"
         "R resets. Pointer: left drag orbits, right drag pans, the wheel zooms.\n";
}

Parsed parse_options(int argc, const char* const* argv) {
  Parsed parsed;
  Options& o = parsed.options;
  // Each flag with a value: its parser, false on a bad value.
  const std::map<std::string, std::function<bool(const std::string&)>> valued = {
      {"--port", [&](const std::string& v) { return parse_int(v, 0, 65535, o.port); }},
      {"--bind", [&](const std::string& v) { o.bind = v; return !v.empty(); }},
      {"--model", [&](const std::string& v) { o.model = v; return !v.empty(); }},
      {"--width", [&](const std::string& v) { return parse_int(v, 160, 3840, o.width); }},
      {"--height", [&](const std::string& v) { return parse_int(v, 120, 2160, o.height); }},
      {"--web-root", [&](const std::string& v) { o.web_root = v; return !v.empty(); }},
  };
  bool web_root_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      o.help = true;
      continue;
    }
    if (flag == "--rfb-only") {
      o.rfb_only = true;
      continue;
    }
    const auto parser = valued.find(flag);
    if (parser == valued.end()) {
      parsed.error = "unknown argument '" + flag + "'";
      return parsed;
    }
    if (i + 1 >= argc) {
      parsed.error = flag + " needs a value";
      return parsed;
    }
    const std::string value = argv[++i];
    if (!parser->second(value)) {
      parsed.error = "bad value '" + value + "' for " + flag;
      return parsed;
    }
    web_root_given = web_root_given || flag == "--web-root";
  }
  if (o.rfb_only && web_root_given) parsed.error = "--rfb-only serves no page; drop --web-root";
  return parsed;
}

}  // namespace mujoco_rfb
