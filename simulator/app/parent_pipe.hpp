// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's end of the ready pipe its parent (sim_manager) hands it as --ready-fd: the descriptor checked
// before anything else is opened, and whole lines written to it (their grammar is contract/ready_line.hpp).
#pragma once

#include <string>

namespace rfbsim::sim {

/// --ready-fd must name a descriptor our parent opened for writing. Checked before we open anything: were it
/// closed, the number could later be reused by one of our own sockets, and the ready line would go there.
/// Throws std::runtime_error naming the problem.
void check_ready_fd(int fd);

/// Writes one whole line to the parent's pipe. Returns the error in words, or "" when it was written.
std::string write_line(int fd, const std::string& line);

}  // namespace rfbsim::sim
