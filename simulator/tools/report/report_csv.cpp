// SPDX-License-Identifier: GPL-2.0-or-later
// sessions.csv, summary.csv and pairs.csv.
#include "report_csv.hpp"

#include "report_columns.hpp"
#include "text_format.hpp"

namespace rfbsim::report {

namespace {

void append_line(std::string& out, const std::vector<std::string>& cells) {
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i > 0) out += ',';
    out += cells[i];
  }
  out += '\n';
}

std::string optional_number(const std::optional<double>& value) { return value ? format_number(*value, 6) : ""; }

}  // namespace

std::string sessions_csv(const std::vector<SessionMetrics>& sessions) {
  std::string out;
  std::vector<std::string> cells;
  for (const Column& c : session_columns()) cells.push_back(c.name);
  append_line(out, cells);
  for (const SessionMetrics& m : sessions) {
    cells.clear();
    for (const Column& c : session_columns()) cells.push_back(csv_cell(c.value(m)));
    append_line(out, cells);
  }
  return out;
}

std::vector<std::string> summary_csv_header() {
  std::vector<std::string> names = {"scope", "scenario", "sessions", "excluded_sessions", "video_sessions"};
  for (const Rate& rate : summary_rates()) names.push_back("pct_" + rate.name);
  for (const std::string& column : summarized_columns()) {
    names.push_back(column + "_n");
    names.push_back(column + "_mean");
    names.push_back(column + "_median");
  }
  return names;
}

std::string summary_csv(const std::vector<GroupSummary>& groups) {
  std::string out;
  append_line(out, summary_csv_header());
  for (const GroupSummary& g : groups) {
    std::vector<std::string> cells = {g.all ? "all" : "scenario", csv_field(g.scenario), std::to_string(g.sessions),
                                      std::to_string(g.excluded), std::to_string(g.video)};
    for (const double pct : g.rate_percent) cells.push_back(format_number(pct, 6));
    for (const Statistic& s : g.statistics) {
      cells.push_back(std::to_string(s.n));
      cells.push_back(optional_number(s.mean));
      cells.push_back(optional_number(s.median));
    }
    append_line(out, cells);
  }
  return out;
}

std::string pairs_csv(const std::vector<SessionMetrics>& sessions, const std::vector<VideoPair>& pairs) {
  std::string out;
  std::vector<std::string> cells;
  for (const PairColumn& c : pair_columns()) cells.push_back(c.name);
  append_line(out, cells);
  for (const VideoPair& p : pairs) {
    cells.clear();
    for (const PairColumn& c : pair_columns()) cells.push_back(csv_cell(pair_cell(c, p, sessions)));
    append_line(out, cells);
  }
  return out;
}

}  // namespace rfbsim::report
