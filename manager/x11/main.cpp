// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_session: sim_manager's launcher for an x11 session. One per session, leading the session's process
// group: a private Xvnc display reachable only through a 0600 unix socket, and an unmodified X11 program on it.
#include <cstdio>
#include <string>
#include <vector>

#include "rfbsim/log.hpp"
#include "session_options.hpp"
#include "session_runner.hpp"

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  const rfbsim::x11::ParsedOptions parsed = rfbsim::x11::parse_session_options(args);
  if (parsed.help) {
    std::fputs(rfbsim::x11::session_usage().c_str(), stdout);
    return 0;
  }
  if (!parsed.error.empty()) {
    std::fprintf(stderr, "rfbsim_x11_session: %s (--help shows the usage)\n", parsed.error.c_str());
    return 2;
  }
  rfbsim::log::set_level(parsed.options.log_level);  // checked by the parser
  return rfbsim::x11::run_session(parsed.options);
}
