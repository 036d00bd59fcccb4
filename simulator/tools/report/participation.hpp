// SPDX-License-Identifier: GPL-2.0-or-later
// Participation: whether a session had a participant. A session sim_manager started whose first picture never
// reached a browser (its link unspent: abandoned, or crashed before anyone saw it) had nobody in it, and the
// study's statistics leave it out; sessions without a manager.json (run by hand) always count.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "manager_record.hpp"
#include "session_metrics.hpp"

namespace rfbsim::report {

/// Copies manager.json's state, detail, spent time and session id into `metrics`, its data_incomplete reason
/// when session.json gave none, and a watcher's yoked_to when session.json gave none.
void add_manager_record(const ManagerRecord& record, SessionMetrics& metrics);

/// Why `metrics` is left out of the statistics for want of a participant ("abandoned: ..."), or "" when it
/// had one. A watcher's session (the video condition) is judged alike but never counts: see in_statistics.
std::string exclusion_reason(const SessionMetrics& metrics);

/// Whether `metrics` counts in the statistics (summary.csv, the overview, the measures, the histograms): an
/// interactive session with a participant. Watchers (the video condition) walked nowhere: they are counted
/// apart (GroupSummary::video) and their sources' measures are in pairs.csv instead.
bool in_statistics(const SessionMetrics& metrics);

/// How many sessions were left out for one reason.
struct Exclusion {
  std::string reason;        ///< exclusion_reason()
  std::size_t sessions = 0;  ///< at least 1
};

/// The reasons the interactive `sessions` were left out for, each once with its count, in the order first met.
std::vector<Exclusion> exclusions(const std::vector<SessionMetrics>& sessions);

}  // namespace rfbsim::report
