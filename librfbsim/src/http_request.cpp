// SPDX-License-Identifier: GPL-2.0-or-later
// HTTP request-head parsing and protocol sniffing.
#include "http_request.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace rfbsim::detail {

namespace {

std::string to_lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// RFC 9110 token characters, for methods and header names.
bool is_token(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || std::string_view("!#$%&'*+-.^_`|~").find(static_cast<char>(c)) !=
                                       std::string_view::npos;
  });
}

bool has_control_chars(std::string_view s) {
  return std::any_of(s.begin(), s.end(), [](unsigned char c) { return c < 0x20 && c != '\t'; });
}

HttpParseResult invalid(std::string why) {
  HttpParseResult result;
  result.status = HttpParseResult::Status::Invalid;
  result.error = std::move(why);
  return result;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string HttpRequest::header(const std::string& name) const {
  auto it = headers.find(name);
  return it == headers.end() ? std::string() : it->second;
}

bool HttpRequest::is_websocket_upgrade() const {
  return to_lower(header("upgrade")) == "websocket";
}

HttpParseResult parse_http_request(std::string_view bytes, std::size_t max_head_bytes) {
  const auto end = bytes.find("\r\n\r\n");
  if (end == std::string_view::npos) {
    if (bytes.size() > max_head_bytes) return invalid("request head too large");
    return {};
  }
  if (end + 4 > max_head_bytes) return invalid("request head too large");

  HttpParseResult result;
  result.head_bytes = end + 4;
  std::string_view head = bytes.substr(0, end);

  // Request line: METHOD SP target SP version
  const auto line_end = head.find("\r\n");
  std::string_view line = head.substr(0, line_end);
  const auto sp1 = line.find(' ');
  const auto sp2 = line.rfind(' ');
  if (sp1 == std::string_view::npos || sp2 == sp1) return invalid("malformed request line");
  const std::string_view method = line.substr(0, sp1);
  const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (!is_token(method)) return invalid("malformed method");
  if (target.empty() || target.front() != '/' || target.find(' ') != std::string_view::npos ||
      has_control_chars(target)) {
    return invalid("malformed request target");
  }
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return invalid("unsupported HTTP version");

  auto& request = result.request;
  request.method = std::string(method);
  request.target = std::string(target);
  request.version = std::string(version);
  const auto question = target.find('?');
  request.path = std::string(target.substr(0, question));
  if (question != std::string_view::npos) request.query = std::string(target.substr(question + 1));

  // Header lines: name ":" OWS value OWS
  std::string_view rest = line_end == std::string_view::npos ? std::string_view() : head.substr(line_end + 2);
  while (!rest.empty()) {
    const auto eol = rest.find("\r\n");
    std::string_view header_line = rest.substr(0, eol);
    rest = eol == std::string_view::npos ? std::string_view() : rest.substr(eol + 2);
    const auto colon = header_line.find(':');
    if (colon == std::string_view::npos) return invalid("header line without ':'");
    const std::string_view name = header_line.substr(0, colon);
    const std::string_view value = trim(header_line.substr(colon + 1));
    if (!is_token(name)) return invalid("malformed header name");
    if (has_control_chars(value)) return invalid("control character in header value");
    request.headers[to_lower(name)] = std::string(value);
  }
  result.status = HttpParseResult::Status::Complete;
  return result;
}

WireProtocol sniff_protocol(std::string_view first_bytes) {
  // Every method, so that the HTTP side answers the unsupported ones with 405 instead of libvncserver
  // closing them without a word. None of these can begin an RFB client's first message.
  static constexpr std::array<std::string_view, 9> kHttpMethods = {
      "GET ", "HEAD ", "POST ", "PUT ", "DELETE ", "OPTIONS ", "PATCH ", "TRACE ", "CONNECT "};
  bool could_be_http = false;
  for (const auto method : kHttpMethods) {
    const auto n = std::min(first_bytes.size(), method.size());
    if (first_bytes.substr(0, n) == method.substr(0, n)) could_be_http = true;
  }
  if (first_bytes.empty()) return WireProtocol::Undecided;
  if (!could_be_http) return WireProtocol::Rfb;
  const auto parsed = parse_http_request(first_bytes);
  switch (parsed.status) {
    case HttpParseResult::Status::Incomplete:
      return WireProtocol::Undecided;
    case HttpParseResult::Status::Invalid:
      return WireProtocol::Http;  // the HTTP side answers 400 with the reason
    case HttpParseResult::Status::Complete:
      break;
  }
  return parsed.request.is_websocket_upgrade() ? WireProtocol::WebSocket : WireProtocol::Http;
}

bool percent_decode_path(std::string_view in, std::string& out) {
  out.clear();
  out.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != '%') {
      out.push_back(in[i]);
      continue;
    }
    if (i + 2 >= in.size()) return false;  // a '%' needs two hex digits after it
    const int hi = hex_value(in[i + 1]);
    const int lo = hex_value(in[i + 2]);
    if (hi < 0 || lo < 0) return false;
    const char decoded = static_cast<char>(hi * 16 + lo);
    if (decoded == '\0') return false;
    out.push_back(decoded);
    i += 2;
  }
  return true;
}

}  // namespace rfbsim::detail
