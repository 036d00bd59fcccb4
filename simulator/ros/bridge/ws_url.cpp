// SPDX-License-Identifier: GPL-2.0-or-later
// parse_ws_url after RFC 6455 section 3 (ws-URI and wss-URI: no fragment, default ports 80 and 443) and
// RFC 3986's authority (IPv6 literals in brackets).
#include "ros/bridge/ws_url.hpp"

#include <stdexcept>

namespace rfbsim::ros {

namespace {

[[noreturn]] void fail(std::string_view url, const std::string& why) {
  throw std::invalid_argument("bad WebSocket URL '" + std::string(url) + "': " + why);
}

bool host_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '.' ||
         c == '_';
}

}  // namespace

WsUrl parse_ws_url(std::string_view url) {
  WsUrl parsed;
  for (const char c : url) {
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f) fail(url, "spaces or control characters");
  }
  std::string_view rest;
  if (url.substr(0, 5) == "ws://") {
    rest = url.substr(5);
  } else if (url.substr(0, 6) == "wss://") {
    parsed.tls = true;
    rest = url.substr(6);
  } else {
    fail(url, "the scheme must be ws:// or wss://");
  }
  if (rest.find('#') != std::string_view::npos) fail(url, "a WebSocket URL has no fragment");

  // Authority up to the first '/' or '?'.
  const std::size_t end = rest.find_first_of("/?");
  std::string_view authority = rest.substr(0, end);
  parsed.resource = end == std::string_view::npos ? "/" : std::string(rest.substr(end));
  if (parsed.resource.front() == '?') parsed.resource.insert(0, "/");
  if (authority.find('@') != std::string_view::npos) fail(url, "user info is not allowed (use a token)");

  std::string_view port_text;
  if (!authority.empty() && authority.front() == '[') {
    const std::size_t close = authority.find(']');
    if (close == std::string_view::npos) fail(url, "unclosed '[' in the host");
    parsed.host = std::string(authority.substr(1, close - 1));
    for (const char c : parsed.host) {
      const bool hex = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
      if (!hex && c != ':' && c != '.') fail(url, "a bracketed host must be an IPv6 address");
    }
    const std::string_view after = authority.substr(close + 1);
    if (!after.empty()) {
      if (after.front() != ':') fail(url, "junk after the IPv6 address");
      port_text = after.substr(1);
      if (port_text.empty()) fail(url, "empty port");
    }
  } else {
    const std::size_t colon = authority.find(':');
    parsed.host = std::string(authority.substr(0, colon));
    if (colon != std::string_view::npos) {
      port_text = authority.substr(colon + 1);
      if (port_text.empty()) fail(url, "empty port");
    }
    for (const char c : parsed.host) {
      if (!host_char(c)) fail(url, "bad character in the host");
    }
  }
  if (parsed.host.empty()) fail(url, "no host");

  parsed.port = parsed.tls ? 443 : 80;
  if (!port_text.empty()) {
    if (port_text.size() > 5) fail(url, "bad port");
    int port = 0;
    for (const char c : port_text) {
      if (c < '0' || c > '9') fail(url, "bad port");
      port = port * 10 + (c - '0');
    }
    if (port < 1 || port > 65535) fail(url, "port out of range");
    parsed.port = port;
  }
  return parsed;
}

}  // namespace rfbsim::ros
