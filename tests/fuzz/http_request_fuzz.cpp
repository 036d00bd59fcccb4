// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: librfbsim's HTTP request-head parser, its protocol sniffer and its path decoder.
// Invariants: a Complete head ends at its blank line and reads back the same when written out again; an
// Incomplete one has no blank line yet; a WebSocket sniff means a complete upgrade request; a decoded path
// never holds a NUL and is no longer than its encoding.
#include <string>

#include "fuzz_check.hpp"
#include "http_request.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::detail;

namespace {

// The head as a client would send it: request line, one line per header, blank line.
std::string write_head(const HttpRequest& request) {
  std::string head = request.method + " " + request.target + " " + request.version + "\r\n";
  for (const auto& [name, value] : request.headers) head += name + ": " + value + "\r\n";
  return head + "\r\n";
}

bool same_request(const HttpRequest& a, const HttpRequest& b) {
  return a.method == b.method && a.target == b.target && a.path == b.path && a.query == b.query &&
         a.version == b.version && a.headers == b.headers;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes = rfbsim::fuzz::as_text(data, size);
  const HttpParseResult parsed = parse_http_request(bytes);
  switch (parsed.status) {
    case HttpParseResult::Status::Incomplete:
      check(bytes.find("\r\n\r\n") == std::string_view::npos, "Incomplete although the head has ended");
      check(bytes.size() <= kMaxHttpHeadBytes, "Incomplete beyond the head size limit");
      break;
    case HttpParseResult::Status::Invalid:
      check(!parsed.error.empty(), "Invalid without a reason");
      break;
    case HttpParseResult::Status::Complete: {
      const HttpRequest& request = parsed.request;
      check(parsed.head_bytes >= 4 && parsed.head_bytes <= bytes.size() && parsed.head_bytes <= kMaxHttpHeadBytes,
            "head_bytes out of range");
      check(bytes.substr(parsed.head_bytes - 4, 4) == "\r\n\r\n", "head_bytes does not end at the blank line");
      check(!request.target.empty() && request.target.front() == '/', "target not starting with '/'");
      check(request.path + (request.target.find('?') == std::string::npos ? "" : "?" + request.query) ==
                request.target,
            "path and query do not make up the target");
      check(request.version == "HTTP/1.1" || request.version == "HTTP/1.0", "unexpected version accepted");
      for (const auto& [name, value] : request.headers) {
        for (const char c : name) check(c < 'A' || c > 'Z', "header name not lower-cased");
        check(value.find_first_of("\r\n") == std::string::npos, "line break in a header value");
      }
      // What was parsed, written out again, parses to the same request (and the head alone suffices).
      const HttpParseResult again = parse_http_request(write_head(request));
      check(again.status == HttpParseResult::Status::Complete && same_request(again.request, request),
            "request does not round-trip");
      const HttpParseResult head_only = parse_http_request(bytes.substr(0, parsed.head_bytes));
      check(head_only.status == HttpParseResult::Status::Complete && same_request(head_only.request, request),
            "the head alone parses differently");
      // The decoder: a success never yields a NUL and never grows the text.
      std::string decoded;
      if (percent_decode_path(request.path, decoded)) {
        check(decoded.find('\0') == std::string::npos, "decoded path holds a NUL");
        check(decoded.size() <= request.path.size(), "decoded path longer than its encoding");
      }
      break;
    }
  }
  // The sniffer agrees with the parser on what a WebSocket upgrade is.
  const WireProtocol protocol = sniff_protocol(bytes);
  if (protocol == WireProtocol::WebSocket) {
    check(parsed.status == HttpParseResult::Status::Complete && parsed.request.is_websocket_upgrade(),
          "sniffed WebSocket without a complete upgrade request");
  }
  if (bytes.empty()) check(protocol == WireProtocol::Undecided, "empty input decided");
  // On raw bytes: a NUL only comes out if one went in unescaped (a request target never holds one).
  std::string decoded;
  if (percent_decode_path(bytes, decoded) && bytes.find('\0') == std::string_view::npos) {
    check(decoded.find('\0') == std::string::npos, "decoded NUL");
  }
  return 0;
}
