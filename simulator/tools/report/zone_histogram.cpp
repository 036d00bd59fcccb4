// SPDX-License-Identifier: GPL-2.0-or-later
// Hall-zone histograms: binning and drawing.
#include "zone_histogram.hpp"

#include <algorithm>

#include "text_format.hpp"

namespace rfbsim::report {

namespace {

constexpr double kPanelWidth = 170.0;  // px per zone
constexpr double kBarsWidth = 140.0;   // px of bars in a panel
constexpr double kBarsHeight = 90.0;   // px of the tallest bar
constexpr double kTop = 22.0;          // px above the bars: the zone's name
constexpr double kLeft = 22.0;         // px left of the bars: the count axis
constexpr const char* kZoneNames[4] = {"intimate &lt; 0.45 m", "personal 0.45&#8211;1.2 m", "social 1.2&#8211;3.6 m",
                                       "public &#8805; 3.6 m"};

// The bin of a percentage; compared before converting, so that no value (not even NaN) converts out of range.
std::size_t bin_of(double percent) {
  if (!(percent > 0.0)) return 0;
  if (percent >= 90.0) return 9;
  return static_cast<std::size_t>(percent / 10.0);
}

std::string text(double x, double y, const char* anchor, const std::string& content) {
  return "<text x=\"" + format_fixed(x, 1) + "\" y=\"" + format_fixed(y, 1) + "\" text-anchor=\"" + anchor + "\">" +
         content + "</text>";
}

}  // namespace

ZoneBins zone_bins(const std::vector<const SessionMetrics*>& sessions) {
  ZoneBins bins{};
  for (const SessionMetrics* m : sessions) {
    if (!m->robot) continue;
    const RobotMetrics& r = *m->robot;
    const double percents[4] = {r.pct_intimate, r.pct_personal, r.pct_social, r.pct_public};
    for (std::size_t zone = 0; zone < 4; ++zone) ++bins[zone][bin_of(percents[zone])];
  }
  return bins;
}

std::string zone_histogram_svg(const ZoneBins& bins) {
  int most = 1;
  for (const auto& zone : bins) most = std::max(most, *std::max_element(zone.begin(), zone.end()));
  const double height = kTop + kBarsHeight + 30.0;
  std::string out = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + format_fixed(4 * kPanelWidth, 0) +
                    "\" height=\"" + format_fixed(height, 0) + "\" font-family=\"sans-serif\" font-size=\"11\">";
  const double bar = kBarsWidth / 10.0;
  for (std::size_t zone = 0; zone < 4; ++zone) {
    const double left = static_cast<double>(zone) * kPanelWidth + kLeft;
    const double base = kTop + kBarsHeight;
    out += text(left + kBarsWidth / 2, 14.0, "middle", kZoneNames[zone]);
    for (std::size_t i = 0; i < 10; ++i) {
      const int n = bins[zone][i];
      if (n == 0) continue;
      const double h = kBarsHeight * n / most;
      out += "<rect fill=\"#5b8bd0\" x=\"" + format_fixed(left + static_cast<double>(i) * bar + 1, 1) + "\" y=\"" +
             format_fixed(base - h, 1) + "\" width=\"" + format_fixed(bar - 2, 1) + "\" height=\"" +
             format_fixed(h, 1) + "\"><title>" + std::to_string(n) + " sessions at " + std::to_string(10 * i) +
             "&#8211;" + std::to_string(10 * i + 10) + " %</title></rect>";
    }
    // Axes: the base line with 0, 50 and 100 %, and the shared count at the top.
    out += "<path stroke=\"#444\" fill=\"none\" d=\"M" + format_fixed(left, 1) + " " + format_fixed(kTop, 1) + "V" +
           format_fixed(base, 1) + "H" + format_fixed(left + kBarsWidth, 1) + "\"/>";
    out += text(left, base + 13, "middle", "0");
    out += text(left + kBarsWidth / 2, base + 13, "middle", "50");
    out += text(left + kBarsWidth, base + 13, "middle", "100");
    out += text(left - 3, kTop + 8, "end", std::to_string(most));
    out += text(left - 3, base, "end", "0");
  }
  out += "<text x=\"" + format_fixed(2 * kPanelWidth, 0) + "\" y=\"" + format_fixed(height - 3, 0) +
         "\" text-anchor=\"middle\">% of samples in the zone (sessions per 10-point bin)</text></svg>";
  return out;
}

}  // namespace rfbsim::report
