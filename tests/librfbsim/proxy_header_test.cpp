// SPDX-License-Identifier: GPL-2.0-or-later
// PROXY protocol version 1 headers: what a relay in front of librfbsim sends, and what is refused.
#include <catch2/catch.hpp>

#include "proxy_header.hpp"

using rfbsim::detail::parse_proxy_header;
using ProxyStatus = rfbsim::detail::ProxyHeader::Status;

TEST_CASE("a TCP4 header gives the source address and its length, the client's bytes follow") {
  const std::string line = "PROXY TCP4 203.0.113.5 127.0.0.1 51234 40000\r\n";
  const auto header = parse_proxy_header(line + "RFB 003.008\n");
  CHECK(header.status == ProxyStatus::Valid);
  CHECK(header.length == line.size());
  CHECK(header.source == "203.0.113.5");
}

TEST_CASE("TCP6 and UNKNOWN headers are valid too") {
  const auto six = parse_proxy_header("PROXY TCP6 2001:db8::1 ::1 443 40000\r\n");
  CHECK(six.status == ProxyStatus::Valid);
  CHECK(six.source == "2001:db8::1");
  const auto unknown = parse_proxy_header("PROXY UNKNOWN\r\n");
  CHECK(unknown.status == ProxyStatus::Valid);
  CHECK(unknown.source.empty());
  CHECK(unknown.length == 15);
}

TEST_CASE("exactly \"PROXY UNKNOWN view-only\" marks a watcher") {
  const std::string line = "PROXY UNKNOWN view-only\r\n";
  const auto watcher = parse_proxy_header(line + "RFB 003.008\n");
  CHECK(watcher.status == ProxyStatus::Valid);
  CHECK(watcher.view_only);
  CHECK(watcher.length == line.size());
  CHECK(watcher.source.empty());
}

TEST_CASE("any other UNKNOWN text is a plain UNKNOWN") {
  CHECK_FALSE(parse_proxy_header("PROXY UNKNOWN\r\n").view_only);
  // Other relays may put anything after UNKNOWN: still valid, never view-only unless it is the exact word.
  for (const char* other : {"PROXY UNKNOWN view-only2\r\n", "PROXY UNKNOWN View-Only\r\n", "PROXY UNKNOWN view\r\n",
                            "PROXY UNKNOWN view-only extra\r\n", "PROXY UNKNOWN  view-only\r\n",
                            "PROXY UNKNOWN view-only \r\n", "PROXY UNKNOWN 1.2.3.4 5.6.7.8 1 2\r\n"}) {
    const auto header = parse_proxy_header(other);
    INFO(other);
    CHECK(header.status == ProxyStatus::Valid);
    CHECK_FALSE(header.view_only);
  }
}

TEST_CASE("the word \"view-only\" elsewhere than after UNKNOWN marks nothing, and a TCP line stays what it was") {
  CHECK(parse_proxy_header("PROXY view-only\r\n").status == ProxyStatus::Invalid);
  const auto tcp = parse_proxy_header("PROXY TCP4 203.0.113.5 127.0.0.1 51234 40000\r\n");
  CHECK(tcp.status == ProxyStatus::Valid);
  CHECK_FALSE(tcp.view_only);
}

TEST_CASE("a watcher's line still arriving waits, and marks nothing yet") {
  const auto partial = parse_proxy_header("PROXY UNKNOWN view-on");
  CHECK(partial.status == ProxyStatus::Incomplete);
  CHECK_FALSE(partial.view_only);
}

TEST_CASE("a header still arriving waits, at most 107 bytes") {
  CHECK(parse_proxy_header("").status == ProxyStatus::Incomplete);
  CHECK(parse_proxy_header("PRO").status == ProxyStatus::Incomplete);
  CHECK(parse_proxy_header("PROXY TCP4 203.0.113.5 127.0.0.1 5").status == ProxyStatus::Incomplete);
  CHECK(parse_proxy_header("PROXY " + std::string(101, 'x')).status == ProxyStatus::Invalid);
}

TEST_CASE("anything else is refused: other protocols, bad addresses, ports and fields") {
  CHECK(parse_proxy_header("RFB 003.008\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("GET / HTTP/1.1\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4 203.0.113 127.0.0.1 1 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4 2001:db8::1 127.0.0.1 1 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4 203.0.113.5 127.0.0.1 65536 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4 203.0.113.5 127.0.0.1 01 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4 203.0.113.5 127.0.0.1 1\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY TCP4  203.0.113.5 127.0.0.1 1 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header("PROXY UDP4 203.0.113.5 127.0.0.1 1 2\r\n").status == ProxyStatus::Invalid);
  CHECK(parse_proxy_header(std::string("PROXY TCP4 203.0.113.5\0 127.0.0.1 1 2\r\n", 39)).status == ProxyStatus::Invalid);
}
