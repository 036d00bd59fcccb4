// SPDX-License-Identifier: GPL-2.0-or-later
// PROXY protocol version 1 lines.
#include "http/proxy_line.hpp"

namespace rfbsim::manager {

namespace {

namespace ip = boost::asio::ip;

ip::address unmapped(ip::address address) {
  if (address.is_v6() && address.to_v6().is_v4_mapped()) return ip::make_address_v4(ip::v4_mapped, address.to_v6());
  return address;
}

bool scoped(const ip::address& address) { return address.is_v6() && address.to_v6().scope_id() != 0; }

}  // namespace

std::string proxy_line(const ip::tcp::endpoint& remote, const ip::tcp::endpoint& local) {
  const ip::address source = unmapped(remote.address());
  const ip::address destination = unmapped(local.address());
  if (source.is_v4() != destination.is_v4() || scoped(source) || scoped(destination)) return "PROXY UNKNOWN\r\n";
  return std::string("PROXY ") + (source.is_v4() ? "TCP4 " : "TCP6 ") + source.to_string() + " " +
         destination.to_string() + " " + std::to_string(remote.port()) + " " + std::to_string(local.port()) + "\r\n";
}

}  // namespace rfbsim::manager
