// SPDX-License-Identifier: GPL-2.0-or-later
// Hall-zone histograms for report.html: for a group of sessions, how many sessions spent how much of their
// time with the closest person in each zone, as inline SVG.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "session_metrics.hpp"

namespace rfbsim::report {

/// Bins of 10 percentage points: [0, 10), [10, 20), ..., [90, 100]; per zone (intimate, personal, social,
/// public) the number of sessions whose share of samples in that zone falls in each bin. Sessions without
/// robot metrics are not counted.
using ZoneBins = std::array<std::array<int, 10>, 4>;
ZoneBins zone_bins(const std::vector<const SessionMetrics*>& sessions);

/// Four small histograms side by side, one per zone, on a shared count axis.
std::string zone_histogram_svg(const ZoneBins& bins);

}  // namespace rfbsim::report
