// SPDX-License-Identifier: GPL-2.0-or-later
// client_address: the participant's address behind trusted proxies, and address ranges.
#include "http/client_address.hpp"

#include <catch2/catch.hpp>

using rfbsim::manager::address_text;
using rfbsim::manager::AddressRange;
using rfbsim::manager::client_address;
using rfbsim::manager::parse_address;
using rfbsim::manager::parse_address_range;
using rfbsim::manager::range_contains;

namespace {
std::vector<AddressRange> ranges(std::initializer_list<const char*> texts) {
  std::vector<AddressRange> out;
  for (const char* text : texts) out.push_back(*parse_address_range(text));
  return out;
}
}  // namespace

TEST_CASE("address ranges parse in both families and contain what they should") {
  const auto v4 = parse_address_range("10.1.0.0/16");
  REQUIRE(v4);
  CHECK(range_contains(*v4, *parse_address("10.1.200.3")));
  CHECK_FALSE(range_contains(*v4, *parse_address("10.2.0.1")));
  const auto v6 = parse_address_range("fd00::/8");
  REQUIRE(v6);
  CHECK(range_contains(*v6, *parse_address("fd12:3456::1")));
  CHECK_FALSE(range_contains(*v6, *parse_address("fe80::1")));
  // An IPv4 range holds the IPv4-mapped form the socket may report.
  CHECK(range_contains(*v4, *parse_address("::ffff:10.1.2.3")));
  CHECK(range_contains(*parse_address_range("0.0.0.0/0"), *parse_address("192.0.2.1")));
}

TEST_CASE("bad ranges are refused") {
  CHECK_FALSE(parse_address_range(""));
  CHECK_FALSE(parse_address_range("10.0.0.0/33"));
  CHECK_FALSE(parse_address_range("10.0.0.0/"));
  CHECK_FALSE(parse_address_range("10.0.0.0/8x"));
  CHECK_FALSE(parse_address_range("::1/129"));
  CHECK_FALSE(parse_address_range("example.org"));
  CHECK_FALSE(parse_address_range("10.0.0.256"));
}

TEST_CASE("one machine has one canonical text") {
  CHECK(address_text(*parse_address("::ffff:127.0.0.1")) == "127.0.0.1");
  CHECK(address_text(*parse_address("127.0.0.1")) == "127.0.0.1");
  CHECK(address_text(*parse_address("2001:DB8:0:0::1")) == "2001:db8::1");
  CHECK(address_text(*parse_address("[::1]")) == "::1");
}

TEST_CASE("X-Forwarded-For counts only from a trusted peer") {
  const auto trusted = ranges({"10.0.0.5"});
  CHECK(client_address("198.51.100.7", "203.0.113.9", trusted) == "198.51.100.7");
  CHECK(client_address("10.0.0.5", "203.0.113.9", trusted) == "203.0.113.9");
  CHECK(client_address("10.0.0.5", "", trusted) == "10.0.0.5");
}

TEST_CASE("the rightmost untrusted entry is the client, and made-up entries to its left are ignored") {
  const auto trusted = ranges({"10.0.0.0/8"});
  CHECK(client_address("10.0.0.5", "1.2.3.4, 203.0.113.9", trusted) == "203.0.113.9");
  CHECK(client_address("10.0.0.5", "1.2.3.4, 203.0.113.9, 10.0.0.9", trusted) == "203.0.113.9");
}

TEST_CASE("garbage in X-Forwarded-For stops the walk at the last address believed") {
  const auto trusted = ranges({"10.0.0.0/8"});
  CHECK(client_address("10.0.0.5", "203.0.113.9, not-an-address", trusted) == "10.0.0.5");
}

TEST_CASE("a trusted peer in IPv4-mapped form is trusted, and an IPv6 entry with spaces around is the client") {
  const auto trusted = ranges({"10.0.0.0/8"});
  CHECK(client_address("::ffff:10.0.0.5", " 2001:db8::7 ", trusted) == "2001:db8::7");
}

TEST_CASE("an IPv4 client counts as itself, an IPv6 client as its /64") {
  using rfbsim::manager::limit_key;
  CHECK(limit_key("203.0.113.9") == "203.0.113.9");
  CHECK(limit_key("::ffff:203.0.113.9") == "203.0.113.9");
  CHECK(limit_key("2001:db8:1:2:aaaa:bbbb:cccc:dddd") == "2001:db8:1:2::/64");
  // Two addresses a machine draws from its one /64 share a key; the neighbouring /64 does not.
  CHECK(limit_key("2001:db8:1:2::1") == limit_key("2001:db8:1:2:ffff::9"));
  CHECK(limit_key("2001:db8:1:3::1") != limit_key("2001:db8:1:2::1"));
  CHECK(limit_key("::1") == "::/64");
  CHECK(limit_key("unknown") == "unknown");
}
