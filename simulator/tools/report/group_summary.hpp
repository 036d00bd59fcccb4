// SPDX-License-Identifier: GPL-2.0-or-later
// GroupSummary: the overall tables: for all sessions and for each scenario, the SEAN-EP rates (percent of
// sessions) and the mean and median of every summarized sessions.csv column, over the interactive sessions
// that had a participant (watchers of the video condition are counted apart).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "session_metrics.hpp"

namespace rfbsim::report {

/// A yes/no property of a session, reported as a percentage of a group's sessions.
struct Rate {
  std::string name;     ///< summary.csv's column is pct_<name>
  std::string meaning;  ///< one line for the report
  std::function<bool(const SessionMetrics&)> holds;
  /// % of sessions the SEAN-EP paper reports for this rate (372 sessions; docs/sources.md); none where
  /// the paper gives no figure.
  std::optional<double> paper_percent;
};

/// The rates, in order: timed_out, completed, never_moved, found_robot, robot_within_0_45,
/// robot_within_1_2, robot_gap_within_0_45, robot_gap_within_1_2, robot_caused_intimate,
/// avatar_pushed_robot, avatar_person_collision.
const std::vector<Rate>& summary_rates();

/// Sessions the SEAN-EP paper's rates (Rate::paper_percent) are over (docs/sources.md).
constexpr int kSeanSessions = 372;

/// What report.md and report.html say under the overview: where the paper's figures come from and which
/// of our rates compare with them (plain text).
constexpr const char* kPaperRowNote =
    "SEAN-EP paper: the figures the study reports over its 372 sessions. It measured the robot's distance to "
    "the avatar between centres, from ROS logs of poses: compare it with the (centres) rates. The (surfaces) "
    "rates apply the same thresholds to the gap between the bodies (centre distance minus both radii).";

/// The mean and median of one column over the sessions of a group that have a value for it.
struct Statistic {
  std::size_t n = 0;             ///< sessions with a value
  std::optional<double> mean;    ///< none when n is 0
  std::optional<double> median;  ///< the middle value, or the mean of the two middle values
};

/// One group's line of summary.csv.
struct GroupSummary {
  bool all = false;      ///< all sessions; otherwise one scenario's
  std::string scenario;  ///< the scenario's name ("" for all)
  std::size_t sessions = 0;  ///< N: sessions in the statistics
  std::size_t excluded = 0;  ///< the group's interactive sessions left out: no participant (exclusion_reason)
  std::size_t video = 0;     ///< the group's watchers (the video condition): counted apart, never measured
  std::vector<double> rate_percent;    ///< % of sessions, parallel to summary_rates()
  std::vector<Statistic> statistics;   ///< parallel to summarized_columns()
};

/// The names of session_columns() with `summarized` set, in order.
const std::vector<std::string>& summarized_columns();

/// All sessions first, then each scenario in name order. Sessions without a participant (exclusion_reason)
/// are left out of the rates and statistics and counted in `excluded`, watchers (the video condition) in
/// `video`; a scenario whose sessions are all left out still has its line, with N 0.
std::vector<GroupSummary> summarize(const std::vector<SessionMetrics>& sessions);

/// The statistic of `values` (any order).
Statistic statistic_of(std::vector<double> values);

}  // namespace rfbsim::report
