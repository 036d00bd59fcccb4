// SPDX-License-Identifier: GPL-2.0-or-later
// report.html.
#include "report_html.hpp"

#include <map>

#include "participation.hpp"
#include "report_columns.hpp"
#include "text_format.hpp"
#include "zone_histogram.hpp"

namespace rfbsim::report {

namespace {

using Row = std::vector<std::string>;

constexpr const char* kHead = R"(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'">
<title>rfbsim session report</title>
<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
th { background: #f0f0f0; }
details { margin: 0.3em 0; }
figure { margin: 0.5em 0 1em; }
figcaption { font-size: 0.85em; color: #555; max-width: 40em; }
.wide { overflow-x: auto; }
.key-avatar { color: #1f6fd1; } .key-robot { color: #d1421f; } .key-person { color: #777; }
</style></head><body>
)";

// A table; header and cells arrive escaped. Cells that look like numbers are right-aligned.
void html_table(std::string& out, const Row& header, const std::vector<Row>& rows) {
  out += "<table><thead><tr>";
  for (const std::string& h : header) out += "<th>" + h + "</th>";
  out += "</tr></thead><tbody>\n";
  for (const Row& row : rows) {
    out += "<tr>";
    for (const std::string& c : row) {
      const bool number = !c.empty() && c.find_first_not_of("0123456789.-") == std::string::npos;
      out += number ? "<td class=\"n\">" + c + "</td>" : "<td>" + c + "</td>";
    }
    out += "</tr>\n";
  }
  out += "</tbody></table>\n";
}

std::string html_group_name(const GroupSummary& g) {
  return g.all ? "all sessions" : "scenario " + html_escape(g.scenario.empty() ? "(unnamed)" : g.scenario);
}

void overview(std::string& out, const ReportData& data) {
  out += "<h2>Overview (% of sessions)</h2>\n";
  Row header = {"group", "N", "left out"};
  for (const Rate& r : summary_rates()) header.push_back("% " + html_escape(r.meaning));
  std::vector<Row> rows;
  for (const GroupSummary& g : data.groups) {
    Row row = {html_group_name(g), std::to_string(g.sessions), std::to_string(g.excluded)};
    for (const double pct : g.rate_percent) row.push_back(format_fixed(pct, 1));
    rows.push_back(row);
  }
  // The paper's own figures, for comparison, where it gives one.
  Row paper = {"SEAN-EP paper", std::to_string(kSeanSessions), ""};
  for (const Rate& r : summary_rates()) paper.push_back(r.paper_percent ? format_number(*r.paper_percent, 2) : "");
  rows.push_back(paper);
  html_table(out, header, rows);
  out += "<p>" + html_escape(kPaperRowNote) + "</p>\n";

  out += "<h2>Measures (mean and median over the sessions that have a value)</h2>\n";
  for (const GroupSummary& g : data.groups) {
    out += "<h3>" + html_group_name(g) + "</h3>\n";
    rows.clear();
    for (std::size_t i = 0; i < summarized_columns().size(); ++i) {
      const Column& c = session_column(summarized_columns()[i]);
      const Statistic& s = g.statistics[i];
      rows.push_back({"<span title=\"" + html_escape(c.meaning) + "\">" + html_escape(c.name) + "</span>",
                      html_escape(c.unit), std::to_string(s.n), optional_cell(s.mean), optional_cell(s.median)});
    }
    html_table(out, {"measure", "unit", "N", "mean", "median"}, rows);
  }
}

void histograms(std::string& out, const ReportData& data) {
  out += "<h2>Time in Hall's zones (the robot's closest person, the avatar included)</h2>\n";
  std::map<std::string, std::vector<const SessionMetrics*>> by_scenario;
  for (const SessionMetrics& m : data.sessions) {
    if (in_statistics(m)) by_scenario[m.scenario].push_back(&m);  // the participants' sessions only
  }
  for (const auto& [scenario, sessions] : by_scenario) {
    out += "<figure>" + zone_histogram_svg(zone_bins(sessions)) + "<figcaption>Scenario " +
           html_escape(scenario.empty() ? "(unnamed)" : scenario) + ": " + std::to_string(sessions.size()) +
           " sessions; each bar counts the sessions whose share of samples in the zone falls in its 10-point "
           "bin.</figcaption></figure>\n";
  }
}

void session_table(std::string& out, const ReportData& data) {
  out += "<h2>Sessions</h2>\n<p>Every column, unrounded, is in sessions.csv.</p>\n";
  Row header;
  for (const Column& c : session_columns()) {
    if (c.shown) {
      header.push_back("<span title=\"" + html_escape(c.meaning) + "\">" + html_escape(c.name) + "</span>" +
                       (c.unit.empty() ? "" : " (" + html_escape(c.unit) + ")"));
    }
  }
  std::vector<Row> rows;
  for (const SessionMetrics& m : data.sessions) {
    Row row;
    for (const Column& c : session_columns()) {
      if (c.shown) row.push_back(html_escape(display_cell(c.value(m))));
    }
    rows.push_back(row);
  }
  out += "<div class=\"wide\">";
  html_table(out, header, rows);
  out += "</div>\n";
}

void plots(std::string& out, const ReportData& data) {
  if (data.plots.size() != data.sessions.size()) return;
  out += "<h2>Trajectories</h2>\n<p>From above, map metres, north up: <span class=\"key-avatar\">avatar</span>, "
         "<span class=\"key-robot\">robot</span>, <span class=\"key-person\">people</span> (faint); a dot marks "
         "where each began, a square where it ended; walls dark, props light grey.</p>\n";
  for (std::size_t i = 0; i < data.sessions.size(); ++i) {
    const SessionMetrics& m = data.sessions[i];
    if (m.video()) continue;  // a watcher walked nowhere
    out += "<details><summary>" + html_escape(m.folder) + " &#8212; uid " + html_escape(m.uid) + ", " +
           html_escape(m.scenario) + ", " + html_escape(m.outcome.empty() ? "no outcome" : m.outcome) +
           "</summary><figure>" + data.plots[i].svg + "<figcaption>" + html_escape(data.plots[i].caption) +
           "</figcaption></figure></details>\n";
  }
}

// The video condition's pairs, when there are watchers.
void video_pairs(std::string& out, const ReportData& data) {
  if (data.video.watchers == 0) return;
  out += "<h2>Video condition: " + std::to_string(data.video.pairs.size()) + " pairs</h2>\n<p>" +
         html_escape(video_note(data.video)) + " Every column, the source's measures included, is in pairs.csv.</p>\n";
  if (data.video.pairs.empty()) return;
  Row header;
  for (const PairColumn& c : pair_columns()) {
    if (c.shown) {
      header.push_back("<span title=\"" + html_escape(c.meaning) + "\">" + html_escape(c.name) + "</span>" +
                       (c.unit.empty() ? "" : " (" + html_escape(c.unit) + ")"));
    }
  }
  std::vector<Row> rows;
  for (const VideoPair& p : data.video.pairs) {
    Row row;
    for (const PairColumn& c : pair_columns()) {
      if (c.shown) row.push_back(html_escape(display_cell(pair_cell(c, p, data.sessions))));
    }
    rows.push_back(row);
  }
  html_table(out, header, rows);
}

// Uids on two hosts (said whenever the report spans hosts, "none" included) and folders found twice.
void hosts(std::string& out, const ReportData& data) {
  if (!data.duplicates.empty() || host_count(data.sessions) > 1) {
    out += "<h2>Duplicate participants</h2>\n";
    if (data.duplicates.empty()) {
      out += "<p>No uid has sessions on more than one host (" + std::to_string(host_count(data.sessions)) + " hosts).</p>\n";
    } else {
      out += "<p>" + html_escape(kDuplicatesNote) + "</p>\n";
      std::vector<Row> rows;
      for (const DuplicateUid& d : data.duplicates) {
        rows.push_back({html_escape(d.uid), html_escape(joined(d.hosts)), html_escape(joined(d.folders))});
      }
      html_table(out, {"uid", "hosts", "sessions"}, rows);
    }
  }
  if (!data.repeats.empty()) {
    out += "<h2>Sessions found twice</h2>\n<p>Each was reported once, from the first folder found.</p>\n";
    std::vector<Row> rows;
    for (const RepeatedFolder& r : data.repeats) {
      rows.push_back({html_escape(r.folder), html_escape(r.same_as), html_escape(r.why)});
    }
    html_table(out, {"left out", "reported", "why the same"}, rows);
  }
}

// The sessions left out of the statistics (counted per reason), the skipped ones and the warnings.
void left_out(std::string& out, const ReportData& data) {
  if (!data.exclusions.empty()) {
    out += "<h2>Left out of the statistics</h2>\n<p>Sessions nobody took part in: sim_manager's manager.json says "
           "no picture ever reached a participant's browser (the link was never spent). They are in the session "
           "table (link_spent no) and in sessions.csv (in_statistics 0), not in the overview, the measures or the "
           "histograms.</p>\n";
    std::vector<Row> rows;
    for (const Exclusion& e : data.exclusions) rows.push_back({html_escape(e.reason), std::to_string(e.sessions)});
    html_table(out, {"why", "sessions"}, rows);
  }
  if (!data.skipped.empty()) {
    out += "<h2>Skipped sessions</h2>\n";
    std::vector<Row> rows;
    for (const SkippedSession& s : data.skipped) rows.push_back({html_escape(s.folder), html_escape(s.reason)});
    html_table(out, {"folder", "reason"}, rows);
  }
  if (!data.warnings.empty()) {
    out += "<h2>Warnings</h2>\n<ul>\n";
    for (const std::string& w : data.warnings) out += "<li>" + html_escape(w) + "</li>\n";
    out += "</ul>\n";
  }
}

}  // namespace

std::string html_report(const ReportData& data) {
  std::string out = kHead;
  // The maps, drawn once and referenced by the plots.
  if (!data.map_definitions.empty()) {
    out += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"0\" height=\"0\" style=\"position:absolute\"><defs>";
    for (const std::string& d : data.map_definitions) out += d;
    out += "</defs></svg>\n";
  }
  std::string folders;
  for (const std::string& d : data.data_dirs) folders += (folders.empty() ? "" : ", ") + html_escape(d);
  out += std::string("<h1>rfbsim session report</h1>\n<p>") +
         (data.data_dirs.size() == 1 ? "Data folder: " : "Data folders: ") + folders + "<br>" +
         std::to_string(data.sessions.size()) + " sessions reported (" + std::to_string(data.groups.front().sessions) +
         " in the statistics, " + std::to_string(data.groups.front().excluded) +
         " without a participant left out" + html_escape(video_count(data.video)) + "), " +
         std::to_string(data.skipped.size()) +
         " skipped. Definitions of every measure: docs/report.md.</p>\n";
  overview(out, data);
  histograms(out, data);
  session_table(out, data);
  video_pairs(out, data);
  hosts(out, data);
  left_out(out, data);
  plots(out, data);
  out += "</body></html>\n";
  return out;
}

}  // namespace rfbsim::report
