// SPDX-License-Identifier: GPL-2.0-or-later
// Xvnc's command line for one session, and the program's environment. Pure.
#pragma once

#include <string>
#include <vector>

#include "session_options.hpp"

namespace rfbsim::x11 {

/// Xvnc's argv (argv[0] = options.xvnc) for a private display: it writes its display number on `display_fd`
/// when ready (-displayfd), admits X clients only with the cookie in options.xauthority (-auth, no -ac), no
/// X11 over TCP (-nolisten tcp; the abstract and file unix sockets stay: with -displayfd the abstract one is
/// what keeps two servers off one number), RFB only on options.rfb_socket with mode 0600 and no TCP port, no
/// VNC password (the manager alone can reach the socket), every viewer shared, and the screen size fixed
/// (viewers may not resize it). The desktop name is the program's file name (viewers show it as the title).
std::vector<std::string> xvnc_arguments(const SessionOptions& options, int display_fd);

/// The program's environment: `inherited` (NAME=value strings) without DISPLAY and XAUTHORITY, then
/// DISPLAY=:`display` and XAUTHORITY=`xauthority`.
std::vector<std::string> program_environment(const std::vector<std::string>& inherited, int display,
                                             const std::string& xauthority);

}  // namespace rfbsim::x11
