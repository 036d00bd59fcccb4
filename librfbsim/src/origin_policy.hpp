// SPDX-License-Identifier: GPL-2.0-or-later
// Which browser pages may open a WebSocket to a standalone server's port: the Origin check that keeps
// another site's page, opened in a participant's or researcher's browser, from driving the simulator.
// Pure: no sockets. Header-only (inline) so that it needs no new entry in librfbsim's source list.
#pragma once

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::detail {

/// A web origin "scheme://host[:port]", normalised: scheme and host in lower case, IPv6 hosts in
/// brackets, the port always filled in (80 for http, 443 for https when the text names none).
struct WebOrigin {
  std::string scheme;  ///< "http" or "https"
  std::string host;    ///< e.g. "example.org", "127.0.0.1", "[::1]"
  int port = 0;        ///< 1..65535

  bool operator==(const WebOrigin&) const = default;
};

namespace origin_parts {

inline std::string to_lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// 1..65535 written in decimal digits only; 0 when it is not.
inline int parse_port(std::string_view text) {
  if (text.empty() || text.size() > 5) return 0;
  int value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return 0;
    value = value * 10 + (c - '0');
  }
  return value <= 65535 ? value : 0;
}

// Host names and IPv4 addresses: letters, digits, '-' and '.'; IPv6 inside brackets: hex digits, ':'
// and '.'. Anything else (user info, spaces, percent escapes, paths) is not an origin a browser sends.
inline bool valid_host(std::string_view host) {
  if (host.empty()) return false;
  if (host.front() == '[') {
    if (host.size() < 4 || host.back() != ']') return false;
    return std::all_of(host.begin() + 1, host.end() - 1,
                       [](unsigned char c) { return std::isxdigit(c) != 0 || c == ':' || c == '.'; });
  }
  return std::all_of(host.begin(), host.end(),
                     [](unsigned char c) { return std::isalnum(c) != 0 || c == '-' || c == '.'; });
}

// Splits "host[:port]" (a Host header, or an origin's authority) into a lower-case host and a port,
// 0 when none is written. False when either part is malformed.
inline bool split_authority(std::string_view authority, std::string& host, int& port) {
  std::string_view port_text;
  bool has_port = false;
  if (!authority.empty() && authority.front() == '[') {
    const auto close = authority.find(']');
    if (close == std::string_view::npos) return false;
    host = to_lower(authority.substr(0, close + 1));
    const auto rest = authority.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return false;
      port_text = rest.substr(1);
      has_port = true;
    }
  } else {
    const auto colon = authority.rfind(':');
    host = to_lower(authority.substr(0, colon));
    if (colon != std::string_view::npos) {
      port_text = authority.substr(colon + 1);
      has_port = true;
    }
  }
  if (!valid_host(host)) return false;
  port = 0;
  if (has_port) {
    port = parse_port(port_text);
    if (port == 0) return false;
  }
  return true;
}

inline bool is_loopback_host(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "[::1]";
}

}  // namespace origin_parts

/// Parses an Origin header value or an --allow-origin argument; nullopt when it is not an http(s)
/// origin without path, query, user info or stray characters (a trailing "/" is not allowed either).
inline std::optional<WebOrigin> parse_web_origin(std::string_view text) {
  const auto separator = text.find("://");
  if (separator == std::string_view::npos) return std::nullopt;
  WebOrigin origin;
  origin.scheme = origin_parts::to_lower(text.substr(0, separator));
  if (origin.scheme != "http" && origin.scheme != "https") return std::nullopt;
  if (!origin_parts::split_authority(text.substr(separator + 3), origin.host, origin.port)) return std::nullopt;
  if (origin.port == 0) origin.port = origin.scheme == "https" ? 443 : 80;
  return origin;
}

/// Checks one allowed-origin entry: "" when it is "*" or a valid origin, else a message saying why not.
inline std::string allowed_origin_error(std::string_view entry) {
  if (entry == "*" || parse_web_origin(entry)) return {};
  return "allowed origin '" + std::string(entry) +
         "' is neither '*' nor scheme://host[:port] with scheme http or https and nothing after the port";
}

/// Whether a WebSocket upgrade that carries `origin` (its Origin header's value) may proceed, given the
/// request's Host header and the configured list: the page's own origin (http or https on `host`), a
/// loopback origin (127.0.0.1, localhost, [::1], any port) or an entry of `allowed` ("*" = any origin).
inline bool websocket_origin_allowed(std::string_view origin, std::string_view host,
                                     const std::vector<std::string>& allowed) {
  if (std::find(allowed.begin(), allowed.end(), "*") != allowed.end()) return true;
  const auto parsed = parse_web_origin(origin);
  if (!parsed) return false;  // "null" (a sandboxed or file:// page) and garbage alike
  if (origin_parts::is_loopback_host(parsed->host)) return true;
  // The page's own origin: the request's Host under either scheme, since a TLS front end may serve the page
  // over https while this port speaks http. A Host without a port means the origin scheme's default one.
  std::string host_name;
  int host_port = 0;
  if (origin_parts::split_authority(host, host_name, host_port) && host_name == parsed->host) {
    const int default_port = parsed->scheme == "https" ? 443 : 80;
    if ((host_port == 0 ? default_port : host_port) == parsed->port) return true;
  }
  return std::any_of(allowed.begin(), allowed.end(), [&](const std::string& entry) {
    const auto listed = parse_web_origin(entry);
    return listed && *listed == *parsed;
  });
}

}  // namespace rfbsim::detail
