// SPDX-License-Identifier: GPL-2.0-or-later
// The columns of sessions.csv, defined once: name, unit, meaning and how to read each from a session's
// metrics. The CSV, the Markdown and HTML tables and the summary's statistics all take them from here.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "session_metrics.hpp"

namespace rfbsim::report {

/// One cell: empty (not applicable), text, a measurement, a count or a yes/no.
using Value = std::variant<std::monostate, std::string, double, std::int64_t, bool>;

/// One column of sessions.csv.
struct Column {
  std::string name;     ///< the CSV header's name
  std::string unit;     ///< m, s, rad, %, m/s, ...; "" for text, counts and 0/1 flags
  std::string meaning;  ///< one line, for the report's legend (docs/report.md has the full definitions)
  std::function<Value(const SessionMetrics&)> value;
  bool summarized = false;  ///< its mean and median go into summary.csv
  bool shown = false;       ///< in the session table of report.md and report.html (the CSV has them all)
};

/// Every column of sessions.csv, in order: who and what (folder to in_statistics), then the measures.
const std::vector<Column>& session_columns();

/// The measure columns of sessions.csv (duration on), in order: empty in a watcher's row (the video condition);
/// pairs.csv gives them for each watcher's source.
std::vector<Column> measure_columns();

/// The column named `name`; throws std::out_of_range when there is none (a programming error).
const Column& session_column(const std::string& name);

/// A cell for CSV: numbers to six decimals at most, flags as 0 and 1, text escaped, empty as "".
std::string csv_cell(const Value& value);

/// A cell for people (not yet escaped): numbers to three decimals, flags as yes and no, empty as "".
std::string display_cell(const Value& value);

/// The cell as a number (flags 0 or 1); none for empty and text cells.
std::optional<double> numeric_value(const Value& value);

}  // namespace rfbsim::report
