// SPDX-License-Identifier: GPL-2.0-or-later
// report.html: one self-contained page (no scripts, no external resources): the overall tables, Hall-zone
// histograms per scenario, the session table and each session's trajectory plot. Every string from the
// data is escaped, and the page's Content-Security-Policy forbids scripts in case anything slipped through.
#pragma once

#include <string>

#include "report_data.hpp"

namespace rfbsim::report {

/// The whole of report.html.
std::string html_report(const ReportData& data);

}  // namespace rfbsim::report
