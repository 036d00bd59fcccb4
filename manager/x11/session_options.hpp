// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_session's command line, parsed into a plain struct. Pure: no file or descriptor is looked at.
#pragma once

#include <string>
#include <vector>

namespace rfbsim::x11 {

/// What one x11 session runs, as given on the command line.
struct SessionOptions {
  std::string rfb_socket;              ///< --rfb-socket: Xvnc's RFB unix socket (mode 0600), as the ready line says
  std::string xauthority;              ///< --xauthority: the Xauthority file to write (and remove at the end)
  int width = 0;                       ///< --geometry W: the screen's width in pixels
  int height = 0;                      ///< --geometry H: the screen's height in pixels
  int depth = 24;                      ///< --depth: the screen's colour depth in bits (16 or 24)
  int ready_fd = -1;                   ///< --ready-fd: where to write the ready lines; -1: nowhere
  std::string xvnc = "/usr/bin/Xvnc";  ///< --xvnc: the Xvnc binary (TigerVNC)
  std::string log_level = "info";      ///< --log-level: error, warn, info or debug (rfbsim/log.hpp)
  std::vector<std::string> program;    ///< after "--": the program and its arguments (program[0] searched in PATH
                                       ///< when it holds no '/')
};

/// A parse's outcome: the options, or why there are none.
struct ParsedOptions {
  SessionOptions options;
  std::string error;  ///< "" when the options are good; else one line naming the flag and the problem
  bool help = false;  ///< --help was asked for (the options are then not checked)
};

/// Parses the arguments after the program name ("--flag value" or "--flag=value", then "--" and the program).
/// Checks each value: the socket path fits a unix address (at most 107 bytes), the geometry is WxH with
/// each side in 16..8192, the depth is 16 or 24, the ready descriptor is 3 or more, a program is named.
ParsedOptions parse_session_options(const std::vector<std::string>& args);

/// The usage text for --help and after a bad flag.
std::string session_usage();

}  // namespace rfbsim::x11
