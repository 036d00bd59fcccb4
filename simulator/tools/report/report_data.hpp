// SPDX-License-Identifier: GPL-2.0-or-later
// ReportData: everything the report's documents are rendered from, gathered by the report job.
#pragma once

#include <string>
#include <vector>

#include "duplicate_uids.hpp"
#include "group_summary.hpp"
#include "participation.hpp"
#include "session_metrics.hpp"
#include "video_pairs.hpp"

namespace rfbsim::report {

/// A session folder that could not be reported, and why.
struct SkippedSession {
  std::string folder;  ///< relative to the data folder
  std::string reason;  ///< the reader's message (names the file and line) or another failure
};

/// A session folder found again under the data folders (another copy of a reported one), counted once.
struct RepeatedFolder {
  std::string folder;   ///< the copy left out, as found
  std::string same_as;  ///< the folder reported in its place (SessionMetrics::folder)
  std::string why;      ///< how the two were recognised as one session (tools::RepeatedSession::why)
};

/// A session's trajectory plot for report.html.
struct SessionPlot {
  std::string svg;      ///< inline SVG (trajectory_svg)
  std::string caption;  ///< plain text: what is drawn, and why the walls are missing if they are
};

/// The report's content.
struct ReportData {
  std::vector<std::string> data_dirs;   ///< as given on the command line, in order
  std::vector<SessionMetrics> sessions; ///< in folder order
  std::vector<GroupSummary> groups;     ///< summarize(sessions)
  std::vector<Exclusion> exclusions;    ///< exclusions(sessions): left out of groups, with why
  std::vector<SkippedSession> skipped;
  std::vector<std::string> warnings;    ///< reported all the same, e.g. a broken manager.json (names the file)
  std::vector<DuplicateUid> duplicates;  ///< uids with sessions on more than one host (flag_duplicate_uids)
  std::vector<RepeatedFolder> repeats;   ///< folders found twice, reported once
  VideoPairing video;                    ///< pair_watchers(sessions): the video condition's pairs
  std::vector<SessionPlot> plots;            ///< parallel to sessions (a watcher's is empty); may be empty (no plots)
  std::vector<std::string> map_definitions;  ///< MapDrawing::definition of every map the plots use
};

}  // namespace rfbsim::report
