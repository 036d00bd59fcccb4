// SPDX-License-Identifier: GPL-2.0-or-later
// A loopback HTTP/1.1 client for tests, over plain TCP or TLS (OpenSSL, no verification): sends exact
// bytes, reads the answer until the server closes, and parses it.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

// A namespace of its own: rfb_test_client.hpp already has rfbsim::test::http_get(int, string, timeout),
// which returns the raw text. Name these qualified (net::http_get) where both headers are in use.
namespace rfbsim::test::net {

/// A parsed HTTP response.
struct HttpResponse {
  /// The status line's code; -1 when no parseable status line came back (refused, reset, timed out
  /// before any answer, TLS handshake failed, not HTTP).
  int status = -1;
  /// Header fields by lower-cased name; a repeated field's values are joined with ", ".
  std::map<std::string, std::string> headers;
  /// The body: everything after the head, cut to Content-Length when given, de-chunked when
  /// Transfer-Encoding is chunked.
  std::string body;
  /// Every byte received, unparsed (for diagnostics).
  std::string raw;
};

/// Connects to 127.0.0.1:`port` (TLS when `tls`: any certificate accepted, no SNI), sends exactly
/// `raw_request` and reads until the server closes, the response is complete (Content-Length reached,
/// or the head of the answer to a "HEAD " request), or `timeout` passes since the call began. The write
/// and the read overlap, so a server that answers early (e.g. 431 to an oversized head) and closes is
/// still heard. Blocks the calling thread; SIGPIPE is held off for that thread during the call.
HttpResponse http_request(int port, const std::string& raw_request, bool tls = false,
                          std::chrono::milliseconds timeout = std::chrono::seconds(5));

/// `GET target HTTP/1.1` with Host: 127.0.0.1:`port`, then `extra_headers` in order, then
/// Connection: close. An extra header named Host or Connection (any case) replaces the default one.
HttpResponse http_get(int port, const std::string& target,
                      const std::vector<std::pair<std::string, std::string>>& extra_headers = {}, bool tls = false,
                      std::chrono::milliseconds timeout = std::chrono::seconds(5));

/// Parses a received response as http_request does (pure; `raw` may be truncated).
HttpResponse parse_http_response(const std::string& raw);

}  // namespace rfbsim::test::net
