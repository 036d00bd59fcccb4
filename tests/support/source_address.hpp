// SPDX-License-Identifier: GPL-2.0-or-later
// Clients from a chosen loopback address, for the tests and benchmarks that need many "addresses" on one machine:
// Linux routes all of 127.0.0.0/8 to loopback, so a socket bound to 127.0.0.2 before connect() reaches a server
// on 127.0.0.1 as another address, and per-address limits can be exercised.
#pragma once

#include <string>

namespace rfbsim::test {

/// A TCP socket bound to `source` (a numeric IPv4 address) and connected to 127.0.0.1:`port` (blocking).
/// `receive_buffer` > 0 sets SO_RCVBUF first, bytes. Returns the descriptor, or -1 with errno set.
int connect_from(const std::string& source, int port, int receive_buffer = 0);

/// A WebSocket opening handshake for `target` (version 13, a fixed key) with `origin` ("" sends none).
std::string upgrade_request(const std::string& target, int port, const std::string& origin);

}  // namespace rfbsim::test
