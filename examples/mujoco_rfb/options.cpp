// SPDX-License-Identifier: GPL-2.0-or-later
// mujoco_rfb's command line: each flag declared once with CLI11 (name, default, range, help), from which parsing
// and --help follow, through rfbsim's cli/ like sim_rfb's (the same words for the same mistakes).
#include "options.hpp"

#include "cli/command_line.hpp"

namespace mujoco_rfb {

namespace {

namespace cli = rfbsim::cli;

// Declares every flag on `app`, bound to `o` (whose initial values are the defaults).
void declare_options(CLI::App& app, Options& o) {
  cli::configure(app);
  app.footer("Keys: W/S or Up/Down move the shoulder, A/D or Left/Right turn the base, Q/E bend the elbow,\n"
             "R resets. Pointer: left drag orbits, right drag pans, the wheel zooms.");
  app.add_flag("-h,--help", o.help, "print this help and exit");
  app.add_option("--port", o.port, "TCP port for RFB, WebSocket and the page; 0 = any free port")
      ->type_name("N")->capture_default_str()->transform(cli::in_range(0, 65535));
  app.add_option("--bind", o.bind, "numeric address to listen on")
      ->type_name("ADDR")->capture_default_str()->check(cli::non_empty());
  app.add_option("--model", o.model, "MJCF model (default: the bundled arm on a table)")
      ->type_name("FILE")->check(cli::non_empty());
  app.add_option("--width", o.width, "frame width in pixels")
      ->type_name("W")->capture_default_str()->transform(cli::in_range(160, 3840));
  app.add_option("--height", o.height, "frame height in pixels")
      ->type_name("H")->capture_default_str()->transform(cli::in_range(120, 2160));
  app.add_option("--web-root", o.web_root, "directory holding the page (default: the built or installed rfbsim page, if any)")
      ->type_name("DIR")->check(cli::non_empty());
  app.add_flag("--rfb-only", o.rfb_only, "serve RFB only (raw and over WebSocket), no page: for sim_manager's sessions");
  cli::add_log_level(app, o.log_level);
}

}  // namespace

std::string usage() {
  Options defaults;
  CLI::App app("A MuJoCo model served to the browser through librfbsim.", "mujoco_rfb");
  declare_options(app, defaults);
  return app.help();
}

Parsed parse_options(int argc, const char* const* argv) {
  Parsed parsed;
  CLI::App app("", "mujoco_rfb");
  declare_options(app, parsed.options);
  parsed.error = cli::parse(app, std::vector<std::string>(argv + 1, argv + argc));
  if (parsed.error.empty() && parsed.options.rfb_only && app.count("--web-root") > 0) {
    parsed.error = "--rfb-only serves no page; drop --web-root";
  }
  return parsed;
}

}  // namespace mujoco_rfb
