// SPDX-License-Identifier: GPL-2.0-or-later
// Who may frame, connect to and administer the manager: response headers, the WebSocket Origin check and
// the admin token check. Pure: no I/O.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rfbsim::manager {

using Headers = std::vector<std::pair<std::string, std::string>>;

/// Headers for every HTML page and session file: framing only by the manager itself and `frame_origins`
/// (CSP frame-ancestors), no caching, no Referer (session URLs carry the token), no MIME sniffing.
Headers page_headers(const std::vector<std::string>& frame_origins);

/// Whether a WebSocket with this Origin header may reach a session. No Origin (not a browser) and the
/// manager's own origin (the Host the request was sent to, any scheme, so that a TLS-terminating proxy in
/// front works) pass, as do the configured frame origins; everything else is refused.
bool websocket_origin_allowed(std::string_view origin, std::string_view host, const std::vector<std::string>& frame_origins);

/// Whether an Authorization header carries the admin token, as "Bearer TOKEN" or HTTP Basic with TOKEN as
/// the password (any user name; what a browser sends after its login prompt). Constant-time comparison.
bool admin_authorized(std::string_view authorization, std::string_view token);

/// Escapes text for HTML element content and attribute values.
std::string html_escape(std::string_view text);

/// Escapes text for a JSON string (without the quotes).
std::string json_escape(std::string_view text);

}  // namespace rfbsim::manager
