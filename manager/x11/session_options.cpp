// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_session's command line: each flag declared once with CLI11, from which parsing and --help follow.
#include "session_options.hpp"

#include <sys/un.h>

#include <algorithm>
#include <charconv>

#include "cli/command_line.hpp"

namespace rfbsim::x11 {

namespace {

constexpr int kMinSide = 16;
constexpr int kMaxSide = 8192;
// sun_path holds the path and its terminating NUL.
constexpr std::size_t kMaxSocketPath = sizeof(sockaddr_un{}.sun_path) - 1;

// A whole decimal side in kMinSide..kMaxSide; false for anything else ("", "12x", "+3", overflow).
bool parse_side(const std::string& text, int& out) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty() || value < kMinSide || value > kMaxSide) {
    return false;
  }
  out = value;
  return true;
}

// "WxH" into width and height; false when it is not that shape or a side is out of range.
bool parse_geometry(const std::string& text, int& width, int& height) {
  const std::size_t x = text.find('x');
  return x != std::string::npos && parse_side(text.substr(0, x), width) && parse_side(text.substr(x + 1), height);
}

// Declares rfbsim_x11_session's flags on `app`, bound to `out`.
void declare_session_options(CLI::App& app, ParsedOptions& out) {
  SessionOptions& o = out.options;
  cli::configure(app);
  // Each flag once: a second --geometry is a mistake in the caller, not an override.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::Throw);
  app.description(
      "Runs PROGRAM on a private X display served by TigerVNC's Xvnc on the unix socket PATH (mode 0600),\n"
      "with a fresh Xauthority cookie. On --ready-fd it writes 'ready unix PATH' and 'x11 display N' once the\n"
      "display is up. It ends when PROGRAM or Xvnc ends, or on SIGTERM, and removes what it made.");
  app.footer(
      "Exit status: PROGRAM's (128+signal when killed), 1 when Xvnc fails or dies, 0 after SIGTERM,\n"
      "2 on bad flags.");
  app.add_flag("-h,--help", out.help, "print this help and exit");
  const std::string socket_expected = "a path of 1 to " + std::to_string(kMaxSocketPath) + " bytes";
  app.add_option("--rfb-socket", o.rfb_socket, "Xvnc's RFB unix socket (mode 0600); required")
      ->type_name("PATH")
      ->check(cli::satisfies([](const std::string& v) { return !v.empty() && v.size() <= kMaxSocketPath; },
                             socket_expected));
  app.add_option("--xauthority", o.xauthority, "the Xauthority file to write (and remove at the end); required")
      ->type_name("PATH")->check(cli::non_empty());
  const std::string geometry_expected =
      "WxH with each side in " + std::to_string(kMinSide) + ".." + std::to_string(kMaxSide);
  app.add_option_function<std::string>(
         "--geometry", [&o](const std::string& v) { parse_geometry(v, o.width, o.height); },
         "the screen's size in pixels; required")
      ->type_name("WxH")
      ->check(cli::satisfies([](const std::string& v) { int w = 0, h = 0; return parse_geometry(v, w, h); },
                             geometry_expected));
  cli::one_of(app.add_option("--depth", o.depth, "the screen's colour depth in bits")->capture_default_str(),
              {"16", "24"});
  // 0..2 are the standard streams, never a pipe of the manager's.
  app.add_option("--ready-fd", o.ready_fd, "where to write the ready lines (default: nowhere)")
      ->type_name("N")->transform(cli::in_range(3, 1 << 20));
  app.add_option("--xvnc", o.xvnc, "the Xvnc binary (TigerVNC)")
      ->type_name("PATH")->capture_default_str()->check(cli::non_empty());
  cli::add_log_level(app, o.log_level);
  app.add_option("PROGRAM", o.program,
                 "after '--': the program and its arguments (searched in PATH when it holds no '/')");
}

}  // namespace

ParsedOptions parse_session_options(const std::vector<std::string>& args) {
  ParsedOptions out;
  CLI::App app("", "rfbsim_x11_session");
  declare_session_options(app, out);
  out.error = cli::parse(app, args);
  if (out.help) {
    out.error.clear();
    return out;
  }
  if (!out.error.empty()) return out;
  // The program and its arguments are exactly what follows the first "--": anything CLI11 took as PROGRAM
  // before it is a stray word.
  const auto dashes = std::find(args.begin(), args.end(), "--");
  const auto after = dashes == args.end() ? std::size_t{0} : static_cast<std::size_t>(args.end() - dashes - 1);
  if (out.options.program.size() != after) {
    out.error = "'" + out.options.program.front() + "' is not a flag (the program goes after '--')";
    return out;
  }

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
  ParsedOptions defaults;
  CLI::App app("", "rfbsim_x11_session");
  declare_session_options(app, defaults);
  return app.help();
}

}  // namespace rfbsim::x11
