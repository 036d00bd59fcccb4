// SPDX-License-Identifier: GPL-2.0-or-later
// The report job: every session folder under one or more data folders read, measured and plotted, and the
// report files written. A session that cannot be read is skipped with its reason; it never stops the rest.
// sim_manager's manager.json, where a folder has one, adds how the session ended and whether anyone saw it.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "report_data.hpp"

namespace rfbsim::report {

/// What a report run did.
struct JobResult {
  std::size_t sessions_found = 0;       ///< folders with a session.json
  std::size_t sessions_reported = 0;
  std::size_t sessions_excluded = 0;    ///< reported but left out of the statistics (no participant)
  std::vector<SkippedSession> skipped;  ///< in folder order
  std::vector<std::string> warnings;    ///< ReportData::warnings; they do not change the exit status
  std::vector<std::string> write_errors;  ///< output files that could not be written, with why
  std::vector<std::filesystem::path> written;  ///< output files written
  std::vector<std::string> duplicate_uids;  ///< duplicate_uid_line() of each uid seen on two hosts; exit status unchanged
  std::vector<RepeatedFolder> repeats;      ///< session folders found twice and reported once
  std::size_t video_sessions = 0;  ///< watchers' sessions (the video condition), counted apart from the statistics
  std::size_t video_pairs = 0;     ///< of those, paired with their source (pairs.csv)

  /// sim_report's exit status: 0 when every session was reported (at least one), else 1.
  [[nodiscard]] int exit_status() const;
};

/// Called after each session with how many are done of how many.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/// Reads every session under `data_dirs` (tools::catalog_sessions: several hosts' data folders or the shared
/// store; a session found twice is reported once; each session's host recorded) and writes sessions.csv,
/// summary.csv, pairs.csv, report.md and report.html into `out_dir`, creating it. A uid with sessions on two
/// hosts is flagged in them. A watcher's session (the video condition: session.json only) is reported in its
/// own row and paired with the session it watched; one whose source is not in the data is a warning.
/// `progress` may be empty.
JobResult run_report(const std::vector<std::filesystem::path>& data_dirs, const std::filesystem::path& out_dir,
                     const ProgressFn& progress = {});

/// run_report over one data folder.
JobResult run_report(const std::filesystem::path& data_dir, const std::filesystem::path& out_dir,
                     const ProgressFn& progress = {});

}  // namespace rfbsim::report
