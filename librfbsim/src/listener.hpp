// SPDX-License-Identifier: GPL-2.0-or-later
// The one listening socket of a server (TCP, or a private unix socket), with errors that name the cause.
#pragma once

#include <sys/types.h>

#include <string>

namespace rfbsim::detail {

/// A bound, listening, non-blocking socket. Owns `fd` and, for a unix socket, the file at `unix_path`
/// (see close_listener).
struct Listener {
  int fd = -1;
  int port = 0;           ///< the TCP port actually bound; 0 for a unix socket
  std::string unix_path;  ///< the unix socket's path; empty for TCP
  dev_t unix_device = 0;  ///< the socket file we created, to remove only that one
  ino_t unix_inode = 0;
};

/// Binds `address` (numeric IPv4 or IPv6) and `port` (0 = any free port) and listens.
/// Throws std::runtime_error naming the address, port and cause (e.g. "port 5900 already in use").
Listener open_listener(const std::string& address, int port);

/// Listens on a unix stream socket at `path`, mode 0600 before anyone can connect. A socket file already
/// there that nobody listens on (left by a crash) is replaced; a live one, or any other kind of file, is
/// an error. Throws std::runtime_error naming the path and cause.
Listener open_unix_listener(const std::string& path);

/// Closes the socket and removes the unix socket file if it is still the one we created.
void close_listener(Listener& listener);

}  // namespace rfbsim::detail
