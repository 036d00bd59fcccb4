// SPDX-License-Identifier: GPL-2.0-or-later
// Flag parsing for rfbsim_x11_session: each flag once, each value checked where it is read.
#include "session_options.hpp"

#include <sys/un.h>

#include <charconv>
#include <set>

namespace rfbsim::x11 {

namespace {

constexpr int kMinSide = 16;
constexpr int kMaxSide = 8192;

// A whole decimal number in [low, high]; false for anything else ("", "12x", "+3", overflow).
bool parse_int(const std::string& text, int low, int high, int& out) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty() || value < low || value > high) {
    return false;
  }
  out = value;
  return true;
}

// One flag's value into `options`; "" or why it is refused.
std::string take(const std::string& flag, const std::string& value, SessionOptions& options) {
  if (flag == "--rfb-socket") {
    // sun_path holds the path and its terminating NUL.
    if (value.empty() || value.size() >= sizeof(sockaddr_un{}.sun_path)) {
      return "--rfb-socket: a path of 1 to " + std::to_string(sizeof(sockaddr_un{}.sun_path) - 1) + " bytes";
    }
    options.rfb_socket = value;
  } else if (flag == "--xauthority") {
    if (value.empty()) return "--xauthority: a path is needed";
    options.xauthority = value;
  } else if (flag == "--geometry") {
    const std::size_t x = value.find('x');
    if (x == std::string::npos || !parse_int(value.substr(0, x), kMinSide, kMaxSide, options.width) ||
        !parse_int(value.substr(x + 1), kMinSide, kMaxSide, options.height)) {
      return "--geometry: '" + value + "' is not WxH with each side in " + std::to_string(kMinSide) + ".." +
             std::to_string(kMaxSide);
    }
  } else if (flag == "--depth") {
    if (value != "16" && value != "24") return "--depth: '" + value + "' is not 16 or 24";
    options.depth = value == "16" ? 16 : 24;
  } else if (flag == "--ready-fd") {
    // 0..2 are the standard streams, never a pipe of the manager's.
    if (!parse_int(value, 3, 1 << 20, options.ready_fd)) return "--ready-fd: '" + value + "' is not a descriptor >= 3";
  } else if (flag == "--xvnc") {
    if (value.empty()) return "--xvnc: a path is needed";
    options.xvnc = value;
  } else {
    return "unknown flag " + flag;
  }
  return "";
}

}  // namespace

ParsedOptions parse_session_options(const std::vector<std::string>& args) {
  ParsedOptions out;
  std::set<std::string> seen;
  std::size_t i = 0;
  for (; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") {
      ++i;
      break;
    }
    if (arg == "--help" || arg == "-h") {
      out.help = true;
      return out;
    }
    // "--flag=value" or "--flag value".
    std::string flag = arg;
    std::string value;
    if (const std::size_t equals = arg.find('='); arg.rfind("--", 0) == 0 && equals != std::string::npos) {
      flag = arg.substr(0, equals);
      value = arg.substr(equals + 1);
    } else if (arg.rfind("--", 0) != 0) {
      out.error = "'" + arg + "' is not a flag (the program goes after '--')";
      return out;
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      out.error = flag + " needs a value";
      return out;
    }
    if (!seen.insert(flag).second) {
      out.error = flag + " is given twice";
      return out;
    }
    if (std::string problem = take(flag, value, out.options); !problem.empty()) {
      out.error = std::move(problem);
      return out;
    }
  }
  out.options.program.assign(args.begin() + static_cast<std::ptrdiff_t>(i), args.end());

  // What every session needs.
  if (out.options.rfb_socket.empty()) {
    out.error = "--rfb-socket is required";
  } else if (out.options.xauthority.empty()) {
    out.error = "--xauthority is required";
  } else if (out.options.width == 0) {
    out.error = "--geometry is required";
  } else if (out.options.program.empty() || out.options.program.front().empty()) {
    out.error = "no program: name it after '--'";
  }
  return out;
}

std::string session_usage() {
  return "usage: rfbsim_x11_session --rfb-socket PATH --xauthority PATH --geometry WxH [--depth 16|24]\n"
         "                          [--ready-fd N] [--xvnc /usr/bin/Xvnc] -- PROGRAM [ARGS...]\n"
         "Runs PROGRAM on a private X display served by TigerVNC's Xvnc on the unix socket PATH (mode 0600),\n"
         "with a fresh Xauthority cookie. On --ready-fd it writes 'ready unix PATH' and 'x11 display N' once the\n"
         "display is up. It ends when PROGRAM or Xvnc ends, or on SIGTERM, and removes what it made.\n"
         "Exit status: PROGRAM's (128+signal when killed), 1 when Xvnc fails or dies, 0 after SIGTERM,\n"
         "2 on bad flags.\n";
}

}  // namespace rfbsim::x11
