// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <string>

#include "http_request.hpp"

using namespace rfbsim::detail;
using Status = HttpParseResult::Status;

TEST_CASE("a complete GET parses into method - path - query and lower-cased headers") {
  const auto r = parse_http_request("GET /a/b.js?x=1 HTTP/1.1\r\nHost: h\r\nX-Thing:  v  \r\n\r\nrest");
  REQUIRE(r.status == Status::Complete);
  CHECK(r.request.method == "GET");
  CHECK(r.request.path == "/a/b.js");
  CHECK(r.request.query == "x=1");
  CHECK(r.request.header("host") == "h");
  CHECK(r.request.header("x-thing") == "v");
  CHECK(r.head_bytes == std::string("GET /a/b.js?x=1 HTTP/1.1\r\nHost: h\r\nX-Thing:  v  \r\n\r\n").size());
}

TEST_CASE("an unfinished head is incomplete - a huge one invalid") {
  CHECK(parse_http_request("GET / HTTP/1.1\r\nHost: h\r\n").status == Status::Incomplete);
  CHECK(parse_http_request(std::string(20000, 'a')).status == Status::Invalid);
}

TEST_CASE("malformed heads are invalid with a reason") {
  CHECK(parse_http_request("GET /\r\n\r\n").status == Status::Invalid);
  CHECK(parse_http_request("GET / HTTP/2.0\r\n\r\n").status == Status::Invalid);
  CHECK(parse_http_request("GET nope HTTP/1.1\r\n\r\n").status == Status::Invalid);
  CHECK(parse_http_request("G(T / HTTP/1.1\r\n\r\n").status == Status::Invalid);
  const auto no_colon = parse_http_request("GET / HTTP/1.1\r\nHost h\r\n\r\n");
  CHECK(no_colon.status == Status::Invalid);
  CHECK(no_colon.error == "header line without ':'");
  CHECK(parse_http_request(std::string("GET / HTTP/1.1\r\nA: b\x01\r\n\r\n")).status == Status::Invalid);
}

TEST_CASE("sniffing tells RFB - WebSocket and HTTP apart") {
  CHECK(sniff_protocol("") == WireProtocol::Undecided);
  CHECK(sniff_protocol("GE") == WireProtocol::Undecided);
  CHECK(sniff_protocol("RFB 003.008\n") == WireProtocol::Rfb);
  CHECK(sniff_protocol("\x16\x03\x01") == WireProtocol::Rfb);  // TLS: libvncserver's business
  CHECK(sniff_protocol("GET / HTTP/1.1\r\nHost: x\r\n") == WireProtocol::Undecided);
  CHECK(sniff_protocol("GET / HTTP/1.1\r\nHost: x\r\n\r\n") == WireProtocol::Http);
  CHECK(sniff_protocol("HEAD / HTTP/1.1\r\n\r\n") == WireProtocol::Http);
  CHECK(sniff_protocol("POST / HTTP/1.1\r\n\r\n") == WireProtocol::Http);  // answered with 405
  CHECK(sniff_protocol("GET /websockify HTTP/1.1\r\nUpgrade: WebSocket\r\nConnection: Upgrade\r\n\r\n") ==
        WireProtocol::WebSocket);
  CHECK(sniff_protocol("GET junk\r\n\r\n") == WireProtocol::Http);  // answered with 400
}

TEST_CASE("percent decoding refuses bad escapes and NUL") {
  std::string out;
  CHECK(percent_decode_path("/a%20b", out));
  CHECK(out == "/a b");
  CHECK_FALSE(percent_decode_path("/a%2", out));
  CHECK_FALSE(percent_decode_path("/a%", out));
  CHECK_FALSE(percent_decode_path("/a%zz", out));
  CHECK_FALSE(percent_decode_path("/a%00", out));
}
