// SPDX-License-Identifier: GPL-2.0-or-later
// parse_ws_url: a ws:// or wss:// URL checked and split before any socket opens, so that a typo in
// --rosbridge-connect fails at start-up naming the URL rather than as a retry loop. Pure.
#pragma once

#include <string>
#include <string_view>

namespace rfbsim::ros {

/// A WebSocket URL's parts.
struct WsUrl {
  bool tls = false;      ///< wss://
  std::string host;      ///< name or address; an IPv6 address without its brackets
  int port = 0;          ///< given, or 80 (ws) / 443 (wss)
  std::string resource;  ///< path and query, "/" when none
};

/// Splits `url` (ws://HOST[:PORT][/PATH][?QUERY] or wss://...). Throws std::invalid_argument naming the URL
/// and the fault: another scheme, no host, user info (send a token instead), a bad port, spaces or
/// control characters, a fragment.
WsUrl parse_ws_url(std::string_view url);

}  // namespace rfbsim::ros
