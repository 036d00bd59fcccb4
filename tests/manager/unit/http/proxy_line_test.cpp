// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "http/proxy_line.hpp"

using boost::asio::ip::make_address;
using boost::asio::ip::tcp;
using rfbsim::manager::proxy_line;

TEST_CASE("an IPv4 browser is named with its address and port, and the manager's") {
  CHECK(proxy_line(tcp::endpoint(make_address("203.0.113.5"), 51234), tcp::endpoint(make_address("10.0.0.2"), 443)) ==
        "PROXY TCP4 203.0.113.5 10.0.0.2 51234 443\r\n");
}

TEST_CASE("an IPv4 browser on a dual-stack socket is named as IPv4") {
  CHECK(proxy_line(tcp::endpoint(make_address("::ffff:203.0.113.5"), 1), tcp::endpoint(make_address("::ffff:10.0.0.2"), 2)) ==
        "PROXY TCP4 203.0.113.5 10.0.0.2 1 2\r\n");
}

TEST_CASE("IPv6 browsers are TCP6, and what the format cannot hold is UNKNOWN") {
  CHECK(proxy_line(tcp::endpoint(make_address("2001:db8::7"), 40000), tcp::endpoint(make_address("2001:db8::1"), 8080)) ==
        "PROXY TCP6 2001:db8::7 2001:db8::1 40000 8080\r\n");
  CHECK(proxy_line(tcp::endpoint(make_address("fe80::1%1"), 1), tcp::endpoint(make_address("fe80::2%1"), 2)) ==
        "PROXY UNKNOWN\r\n");
  CHECK(proxy_line(tcp::endpoint(make_address("2001:db8::7"), 1), tcp::endpoint(make_address("10.0.0.2"), 2)) ==
        "PROXY UNKNOWN\r\n");
}
