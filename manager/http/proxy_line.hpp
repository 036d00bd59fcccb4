// SPDX-License-Identifier: GPL-2.0-or-later
// The PROXY protocol (version 1) line with which the relay names a browser to its session, so that sim_rfb
// records the participant's address rather than the relay's. Pure: endpoints in, a line out.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <string>

namespace rfbsim::manager {

/// "PROXY TCP4 <browser> <manager> <browser port> <manager port>\r\n" (TCP6 alike) for a browser
/// connection from `remote` to the manager's `local` endpoint. IPv4 browsers on a dual-stack socket
/// (::ffff:a.b.c.d) are named as IPv4. "PROXY UNKNOWN\r\n" when the two are of different families or an
/// address carries a scope (fe80::1%eth0), which the line's format cannot hold.
std::string proxy_line(const boost::asio::ip::tcp::endpoint& remote, const boost::asio::ip::tcp::endpoint& local);

}  // namespace rfbsim::manager
