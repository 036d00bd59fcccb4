// SPDX-License-Identifier: GPL-2.0-or-later
// ReportData: everything the report's documents are rendered from, gathered by the report job.
#pragma once

#include <string>
#include <vector>

#include "group_summary.hpp"
#include "participation.hpp"
#include "session_metrics.hpp"

namespace rfbsim::report {

/// A session folder that could not be reported, and why.
struct SkippedSession {
  std::string folder;  ///< relative to the data folder
  std::string reason;  ///< the reader's message (names the file and line) or another failure
};

/// A session's trajectory plot for report.html.
struct SessionPlot {
  std::string svg;      ///< inline SVG (trajectory_svg)
  std::string caption;  ///< plain text: what is drawn, and why the walls are missing if they are
};

/// The report's content.
struct ReportData {
  std::string data_dir;                 ///< as given on the command line
  std::vector<SessionMetrics> sessions; ///< in folder order
  std::vector<GroupSummary> groups;     ///< summarize(sessions)
  std::vector<Exclusion> exclusions;    ///< exclusions(sessions): left out of groups, with why
  std::vector<SkippedSession> skipped;
  std::vector<std::string> warnings;    ///< reported all the same, e.g. a broken manager.json (names the file)
  std::vector<SessionPlot> plots;            ///< parallel to sessions; may be empty (no plots)
  std::vector<std::string> map_definitions;  ///< MapDrawing::definition of every map the plots use
};

}  // namespace rfbsim::report
