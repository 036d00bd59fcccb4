// SPDX-License-Identifier: GPL-2.0-or-later
// URL query strings and percent-encoding, parsed strictly: a malformed link is refused, never guessed at.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rfbsim::manager {

/// A query's parameters in the order given, names and values percent-decoded.
using QueryParams = std::vector<std::pair<std::string, std::string>>;

/// Decodes %XX escapes and '+' (a space in query strings). Nothing for a bad or truncated escape or a
/// decoded NUL or control character.
std::optional<std::string> percent_decode(std::string_view text);

/// Encodes everything but unreserved characters (RFC 3986: letters, digits, - . _ ~).
std::string percent_encode(std::string_view text);

/// Splits "a=1&b=2" into decoded pairs. On a malformed or repeated parameter returns nothing and says why.
std::optional<QueryParams> parse_query(std::string_view query, std::string& error);

/// Splits a request target "/path?query" into its path and query (query empty when there is none).
std::pair<std::string_view, std::string_view> split_target(std::string_view target);

}  // namespace rfbsim::manager
