// SPDX-License-Identifier: GPL-2.0-or-later
// A forked child's signals put back to their defaults before it execs: a blocked or ignored signal survives
// execve, and the parents (sim_manager, which blocks and handles some; rfbsim_x11_session, which blocks its
// signals for a signalfd and ignores SIGPIPE) must not pass theirs on to a session's program.
#pragma once

#include <csignal>

namespace rfbsim::x11 {

/// Unblocks every signal and sets the ones the parents change (SIGPIPE, SIGINT, SIGTERM, SIGCHLD, SIGHUP) back
/// to SIG_DFL. Async-signal-safe: for the child between fork and exec.
inline void reset_signals_for_exec() {
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  for (const int sig : {SIGPIPE, SIGINT, SIGTERM, SIGCHLD, SIGHUP}) ::sigaction(sig, &default_action, nullptr);
}

}  // namespace rfbsim::x11
