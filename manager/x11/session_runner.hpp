// SPDX-License-Identifier: GPL-2.0-or-later
// One x11 session's life: the Xauthority cookie, Xvnc on a free display, the program on that display, the
// ready lines for the manager, then watching both until one ends or a stop signal comes, and the clean-up.
#pragma once

#include "session_options.hpp"

namespace rfbsim::x11 {

/// Runs the session described by `options` in the current directory (Xvnc's log goes to ./xvnc.log) and
/// returns the launcher's exit status: the program's (128 + signal when a signal ended it) when the program
/// ended first; 1 when Xvnc would not start, did not name its display within 10 s, or died; 0 after SIGTERM,
/// SIGINT or SIGHUP; 2 when --ready-fd is not an open descriptor. Always removes, last, the Xauthority file, the
/// RFB socket and the display's files if its server left them. Blocks SIGCHLD, SIGTERM, SIGINT and SIGHUP and
/// ignores SIGPIPE in this process. Errors are one line each through the log sink (rfbsim/log.hpp, on stderr),
/// tagged "[rfbsim_x11_session]".
int run_session(const SessionOptions& options);

}  // namespace rfbsim::x11
