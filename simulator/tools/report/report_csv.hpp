// SPDX-License-Identifier: GPL-2.0-or-later
// sessions.csv, summary.csv and pairs.csv as text (docs/report.md defines every column).
#pragma once

#include <string>
#include <vector>

#include "group_summary.hpp"
#include "session_metrics.hpp"
#include "video_pairs.hpp"

namespace rfbsim::report {

/// A header line of session_columns()' names, then one line per session.
std::string sessions_csv(const std::vector<SessionMetrics>& sessions);

/// summary.csv's column names: scope, scenario, sessions, excluded_sessions, video_sessions, pct_<rate> per rate,
/// then <column>_n,
/// <column>_mean and <column>_median per summarized column.
std::vector<std::string> summary_csv_header();

/// A header line, then one line per group (scope "all" first, then "scenario" lines).
std::string summary_csv(const std::vector<GroupSummary>& groups);

/// pairs.csv: a header line of pair_columns()' names, then one line per pair of `sessions`.
std::string pairs_csv(const std::vector<SessionMetrics>& sessions, const std::vector<VideoPair>& pairs);

}  // namespace rfbsim::report
