// SPDX-License-Identifier: GPL-2.0-or-later
// An X display's files in /tmp: the lock file (/tmp/.X<N>-lock, holding the server's pid as "%10d\n") and the
// listening socket (/tmp/.X11-unix/X<N>). A server that exits cleanly removes both; one killed with SIGKILL
// leaves them, and a later server would then skip (or, without a lock, clobber) that display number. The
// launcher of an x11 session calls remove_stale_display as its last step, and sim_manager after it had to
// SIGKILL a session's whole process group.
#pragma once

#include <string>

namespace rfbsim::x11 {

/// The path of display `display`'s lock file under `tmp_dir` (normally "/tmp").
std::string display_lock_path(int display, const std::string& tmp_dir = "/tmp");

/// The path of display `display`'s listening socket under `tmp_dir` (normally "/tmp").
std::string display_socket_path(int display, const std::string& tmp_dir = "/tmp");

/// Removes display `display`'s lock file and socket when no server holds them any more: the lock's pid is not
/// alive (or the lock is unreadable junk) and nothing accepts on the socket (neither the file nor Linux's
/// abstract twin of the same name). Leaves everything of a display that a live server holds. Returns true when
/// nothing of the display is left afterwards, false when a live server still holds it or a file could not be
/// removed. A negative `display` is an error of the caller's: false, nothing touched.
bool remove_stale_display(int display, const std::string& tmp_dir = "/tmp");

}  // namespace rfbsim::x11
