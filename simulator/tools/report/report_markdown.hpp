// SPDX-License-Identifier: GPL-2.0-or-later
// report.md: the overall tables, the per-group statistics, the session table and the skipped sessions as
// Markdown (GitHub tables), every string from the data escaped.
#pragma once

#include <string>

#include "report_data.hpp"

namespace rfbsim::report {

/// The whole of report.md.
std::string markdown_report(const ReportData& data);

}  // namespace rfbsim::report
