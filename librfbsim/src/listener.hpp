// SPDX-License-Identifier: GPL-2.0-or-later
// open_listener: the one TCP listening socket of a server, with errors that name the cause.
#pragma once

#include <string>

namespace rfbsim::detail {

/// A bound, listening, non-blocking TCP socket.
struct Listener {
  int fd = -1;
  int port = 0;  ///< the port actually bound
};

/// Binds `address` (numeric IPv4 or IPv6) and `port` (0 = any free port) and listens.
/// Throws std::runtime_error naming the address, port and cause (e.g. "port 5900 already in use").
Listener open_listener(const std::string& address, int port);

}  // namespace rfbsim::detail
