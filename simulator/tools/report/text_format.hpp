// SPDX-License-Identifier: GPL-2.0-or-later
// Text for the report's files: numbers written alike everywhere, and every string from session data
// escaped for the format it lands in (CSV, Markdown, HTML and SVG), so that data cannot change the markup.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace rfbsim::report {

/// `value` with `decimals` digits after the point ("%.*f"); "-0.000" comes out as "0.000".
std::string format_fixed(double value, int decimals);

/// An optional measure in a table cell: three decimals, or empty when there is none.
std::string optional_cell(const std::optional<double>& value);

/// `value` with up to `decimals` digits after the point, trailing zeros and a bare point dropped
/// ("5", "0.25"): the compact form for CSV.
std::string format_number(double value, int decimals = 6);

/// One CSV field (RFC 4180): quoted, with quotes doubled, when it holds a comma, quote, CR or LF.
std::string csv_field(std::string_view text);

/// Text for HTML and SVG, in element content or a quoted attribute: & < > " ' as entities.
std::string html_escape(std::string_view text);

/// Text for a Markdown table cell: every ASCII punctuation character backslash-escaped (CommonMark
/// allows that for all of them, so no emphasis, link, raw HTML, entity or cell border can start) and
/// line breaks and tabs turned into spaces.
std::string markdown_escape(std::string_view text);

}  // namespace rfbsim::report
