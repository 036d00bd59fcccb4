// SPDX-License-Identifier: GPL-2.0-or-later
// Pure HTTP/1.1 request-head parsing and first-bytes protocol sniffing; no sockets here.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <string_view>

namespace rfbsim::detail {

/// The head of an HTTP request. Header names are lower-cased; the last repeat of a header wins.
struct HttpRequest {
  std::string method;   ///< e.g. "GET"
  std::string target;   ///< as sent, e.g. "/novnc/core/rfb.js?x=1"
  std::string path;     ///< target up to '?', not yet percent-decoded
  std::string query;    ///< after '?', possibly empty
  std::string version;  ///< "HTTP/1.1" or "HTTP/1.0"
  std::map<std::string, std::string> headers;

  /// Value of a header (name in lower case), or "" when absent.
  [[nodiscard]] std::string header(const std::string& name) const;
  /// Whether the request asks for a WebSocket upgrade (Upgrade: websocket, any case).
  [[nodiscard]] bool is_websocket_upgrade() const;
};

/// Outcome of parsing the bytes received so far.
struct HttpParseResult {
  enum class Status { Incomplete, Complete, Invalid };
  Status status = Status::Incomplete;
  HttpRequest request;       ///< filled when Complete
  std::string error;         ///< why, when Invalid
  std::size_t head_bytes = 0;  ///< bytes up to and including the blank line, when Complete
};

/// Largest request head accepted; more is an Invalid request (431 for a server).
inline constexpr std::size_t kMaxHttpHeadBytes = 16384;

/// Parses a request head (request line and headers up to the blank line) from `bytes`.
HttpParseResult parse_http_request(std::string_view bytes, std::size_t max_head_bytes = kMaxHttpHeadBytes);

/// What a new connection on the shared port speaks, judged from its first bytes.
enum class WireProtocol {
  Undecided,  ///< too few bytes to tell; wait for more (or time out to Rfb)
  Rfb,        ///< anything that is not HTTP: raw RFB, TLS, garbage (libvncserver deals with it)
  WebSocket,  ///< an HTTP GET asking for a WebSocket upgrade
  Http,       ///< a plain HTTP request for the page, a file or a JSON route
};

/// Classifies a connection from the bytes peeked so far. An HTTP-looking start stays Undecided until the
/// whole request head is there, because only the headers tell WebSocket from plain HTTP.
WireProtocol sniff_protocol(std::string_view first_bytes);

/// Decodes %XX escapes of a URL path; returns false on a malformed escape or a decoded NUL.
bool percent_decode_path(std::string_view in, std::string& out);

}  // namespace rfbsim::detail
