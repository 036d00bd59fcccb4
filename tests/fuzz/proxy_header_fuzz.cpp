// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: the PROXY protocol version 1 header parser.
// Invariants: a Valid header is "PROXY ...\r\n" of at most 107 bytes, parses the same on its own and is
// Incomplete one byte short; its source is an address inet_pton reads; Incomplete means no line end yet,
// and every shorter prefix of an Incomplete input is Incomplete too; view_only only for a Valid line that is
// exactly "PROXY UNKNOWN view-only".
#include <arpa/inet.h>

#include <string>

#include "fuzz_check.hpp"
#include "proxy_header.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::detail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes = rfbsim::fuzz::as_text(data, size);
  const ProxyHeader header = parse_proxy_header(bytes);
  switch (header.status) {
    case ProxyHeader::Status::Valid: {
      check(header.length >= 8 && header.length <= kMaxProxyHeaderBytes && header.length <= bytes.size(),
            "length out of range");
      check(bytes.substr(0, 6) == "PROXY ", "valid without the signature");
      check(bytes.substr(header.length - 2, 2) == "\r\n", "length does not end at CR LF");
      check(bytes.substr(0, header.length - 2).find("\r\n") == std::string_view::npos, "CR LF before the end");
      const ProxyHeader alone = parse_proxy_header(bytes.substr(0, header.length));
      check(alone.status == ProxyHeader::Status::Valid && alone.length == header.length &&
                alone.source == header.source && alone.view_only == header.view_only,
            "the header alone parses differently");
      check(parse_proxy_header(bytes.substr(0, header.length - 1)).status == ProxyHeader::Status::Incomplete,
            "a header one byte short is not Incomplete");
      if (!header.source.empty()) {
        unsigned char address[16];
        const int family = header.source.find(':') == std::string::npos ? AF_INET : AF_INET6;
        check(::inet_pton(family, header.source.c_str(), address) == 1, "source is not an address");
      } else {
        check(bytes.substr(6, 7) == "UNKNOWN", "no source but not UNKNOWN");
      }
      check(header.view_only == (bytes.substr(0, header.length) == "PROXY UNKNOWN view-only\r\n"),
            "view_only is not exactly the view-only line");
      break;
    }
    case ProxyHeader::Status::Incomplete:
      check(bytes.size() < kMaxProxyHeaderBytes, "Incomplete beyond the size limit");
      check(!header.view_only, "view_only before the line is whole");
      check(bytes.find("\r\n") == std::string_view::npos, "Incomplete with a line end");
      if (!bytes.empty()) {
        check(parse_proxy_header(bytes.substr(0, bytes.size() - 1)).status == ProxyHeader::Status::Incomplete,
              "a prefix of an Incomplete input is decided");
      }
      break;
    case ProxyHeader::Status::Invalid:
      check(header.length == 0 && header.source.empty() && !header.view_only, "Invalid with a length, source or mark");
      break;
  }
  return 0;
}
