// SPDX-License-Identifier: GPL-2.0-or-later
// Strict query-string parsing for links that arrive from untrusted participants.
#include "http/query.hpp"

namespace rfbsim::manager {

namespace {

int hex_value(char ch) {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

}  // namespace

std::optional<std::string> percent_decode(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    char ch = text[i];
    if (ch == '+') {
      ch = ' ';
    } else if (ch == '%') {
      if (i + 2 >= text.size()) return std::nullopt;  // truncated escape
      const int high = hex_value(text[i + 1]);
      const int low = hex_value(text[i + 2]);
      if (high < 0 || low < 0) return std::nullopt;
      ch = static_cast<char>(high * 16 + low);
      i += 2;
    }
    // Control characters (NUL, newlines...) have no business in a link and would corrupt logs.
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) return std::nullopt;
    out.push_back(ch);
  }
  return out;
}

std::string percent_encode(std::string_view text) {
  static const char* const kHex = "0123456789ABCDEF";
  std::string out;
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    const bool unreserved = (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
                            ch == '-' || ch == '.' || ch == '_' || ch == '~';
    if (unreserved) {
      out.push_back(ch);
    } else {
      out.push_back('%');
      out.push_back(kHex[byte >> 4]);
      out.push_back(kHex[byte & 0xf]);
    }
  }
  return out;
}

std::optional<QueryParams> parse_query(std::string_view query, std::string& error) {
  QueryParams params;
  if (query.empty()) return params;
  std::size_t start = 0;
  for (;;) {
    const std::size_t amp = query.find('&', start);
    const std::string_view part = query.substr(start, amp == std::string_view::npos ? amp : amp - start);
    const std::size_t eq = part.find('=');
    if (part.empty() || eq == 0 || eq == std::string_view::npos) {
      error = "malformed parameter '" + std::string(part.substr(0, 64)) + "' (expected name=value)";
      return std::nullopt;
    }
    auto name = percent_decode(part.substr(0, eq));
    auto value = percent_decode(part.substr(eq + 1));
    if (!name || !value) {
      error = "bad percent-encoding in '" + std::string(part.substr(0, 64)) + "'";
      return std::nullopt;
    }
    for (const auto& [seen, unused] : params) {
      if (seen == *name) {
        error = "parameter '" + seen.substr(0, 64) + "' given twice";
        return std::nullopt;
      }
    }
    params.emplace_back(std::move(*name), std::move(*value));
    if (amp == std::string_view::npos) break;
    start = amp + 1;
  }
  return params;
}

std::pair<std::string_view, std::string_view> split_target(std::string_view target) {
  const std::size_t mark = target.find('?');
  if (mark == std::string_view::npos) return {target, {}};
  return {target.substr(0, mark), target.substr(mark + 1)};
}

}  // namespace rfbsim::manager
