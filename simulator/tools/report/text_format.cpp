// SPDX-License-Identifier: GPL-2.0-or-later
// Number formatting and escaping for CSV, Markdown, HTML and SVG.
#include "text_format.hpp"

#include <cmath>
#include <cstdio>

namespace rfbsim::report {

std::string format_fixed(double value, int decimals) {
  if (!std::isfinite(value)) return std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf");
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  std::string out = text;
  // A value that rounds to zero prints as "-0.00" when it was slightly negative.
  if (out.front() == '-' && out.find_first_not_of("-0.") == std::string::npos) out.erase(0, 1);
  return out;
}

std::string optional_cell(const std::optional<double>& value) { return value ? format_fixed(*value, 3) : ""; }

std::string format_number(double value, int decimals) {
  std::string out = format_fixed(value, decimals);
  if (out.find('.') != std::string::npos && std::isfinite(value)) {
    out.erase(out.find_last_not_of('0') + 1);
    if (out.back() == '.') out.pop_back();
  }
  return out;
}

std::string csv_field(std::string_view text) {
  // A text cell a spreadsheet would take for a formula (a uid "-A1", a name "=cmd|...") gets a leading
  // apostrophe, which spreadsheets show as text; the CSV's own readers see the apostrophe.
  std::string guarded;
  if (!text.empty() && (text[0] == '=' || text[0] == '+' || text[0] == '-' || text[0] == '@')) {
    guarded = "'" + std::string(text);
    text = guarded;
  }
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string markdown_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '\n' || c == '\r' || c == '\t') {
      out += ' ';
    } else if ((c >= '!' && c <= '/') || (c >= ':' && c <= '@') || (c >= '[' && c <= '`') || (c >= '{' && c <= '~')) {
      out += '\\';
      out += c;
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace rfbsim::report
