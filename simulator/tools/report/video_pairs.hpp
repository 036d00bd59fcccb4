// SPDX-License-Identifier: GPL-2.0-or-later
// The video condition in the report (issue 33): a watcher's row made from its session.json, and each watcher
// (B) paired with the interactive session it watched (A, its source) for the paired tests: B's yoked_to is A's
// session id on the same host, and B's replay_of.started_at is A's started_at. pairs.csv and the report's
// "Video condition" section (report_csv, report_markdown, report_html) are one row per pair: who, how much B
// watched, and A's measures.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "report_columns.hpp"
#include "session_metrics.hpp"

namespace rfbsim::tools {
struct WatcherSession;  // watcher_session.hpp, in the tools' common library (private to this one)
}  // namespace rfbsim::tools

namespace rfbsim::report {

/// A watcher's row of the report: who, what it watched and for how long (WatcherMetrics); no measures.
/// Its folder, host and session id are the caller's to set, as for any session.
SessionMetrics watcher_metrics(const tools::WatcherSession& session);

/// One pair of the video condition.
struct VideoPair {
  std::size_t number = 0;   ///< 1, 2, ... in the order of the pairs
  std::size_t source = 0;   ///< index into the sessions of the interactive session watched (A)
  std::size_t watcher = 0;  ///< index into the sessions of the watcher (B)
};

/// The video condition's pairs among a report's sessions.
struct VideoPairing {
  std::vector<VideoPair> pairs;  ///< sorted by the source's session id, then the watcher's
  std::size_t watchers = 0;      ///< watchers' sessions in all, paired or not
  /// One per watcher left without a pair, naming it and the source it names: not in the data, run by hand
  /// (yoked_to null), or a session of that id that is not the one it watched.
  std::vector<std::string> warnings;
};

/// Pairs every watcher in `sessions` with its source (the header says how).
VideoPairing pair_watchers(const std::vector<SessionMetrics>& sessions);

/// What report.md and report.html say above the pair table (plain text): how the pairs are made, that the
/// watchers are not in the statistics, and how many watchers were left without a pair.
std::string video_note(const VideoPairing& pairing);

/// ", N watchers (video condition) counted apart" for the report's opening count; "" without watchers.
std::string video_count(const VideoPairing& pairing);

/// One column of pairs.csv.
struct PairColumn {
  std::string name;     ///< the CSV header's name
  std::string unit;     ///< as Column::unit
  std::string meaning;  ///< one line (docs/report.md has the full definitions)
  std::function<Value(const VideoPair&, const SessionMetrics& source, const SessionMetrics& watcher)> value;
  bool shown = false;  ///< in the pair table of report.md and report.html (the CSV has them all)
};

/// Every column of pairs.csv, in order: the pair, the source and the watcher, then each of sessions.csv's
/// measure columns for the source, prefixed `source_`.
const std::vector<PairColumn>& pair_columns();

/// `column`'s cell for `pair` of `sessions`.
Value pair_cell(const PairColumn& column, const VideoPair& pair, const std::vector<SessionMetrics>& sessions);

}  // namespace rfbsim::report
