// SPDX-License-Identifier: GPL-2.0-or-later
// report.md.
#include "report_markdown.hpp"

#include "report_columns.hpp"
#include "text_format.hpp"

namespace rfbsim::report {

namespace {

using Row = std::vector<std::string>;

// A table. Cells arrive escaped: strings from the data through markdown_escape; column names, units and
// numbers are ours and hold no markup.
void markdown_table(std::string& out, const Row& header, const std::vector<Row>& rows) {
  const auto line = [&](const Row& cells) {
    out += "|";
    for (const std::string& c : cells) out += " " + c + " |";
    out += "\n";
  };
  line(header);
  out += "|";
  for (std::size_t i = 0; i < header.size(); ++i) out += i == 0 ? " --- |" : " ---: |";
  out += "\n";
  for (const Row& r : rows) line(r);
  out += "\n";
}

std::string markdown_group_name(const GroupSummary& g) {
  return g.all ? "all sessions" : "scenario " + markdown_escape(g.scenario.empty() ? "(unnamed)" : g.scenario);
}

std::string with_unit(const Column& c) { return c.unit.empty() ? c.name : c.name + " (" + c.unit + ")"; }

// Strings from the data, each escaped, joined with ", " (an escaped comma would read "\,").
std::string escaped_list(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + markdown_escape(item);
  return out;
}

}  // namespace

std::string markdown_report(const ReportData& data) {
  std::string out = "# rfbsim session report\n\n";
  std::string folders;
  for (const std::string& d : data.data_dirs) folders += (folders.empty() ? "" : ", ") + markdown_escape(d);
  out += (data.data_dirs.size() == 1 ? "Data folder: " : "Data folders: ") + folders + "  \n";
  out += std::to_string(data.sessions.size()) + " sessions reported (" + std::to_string(data.groups.front().sessions) +
         " in the statistics, " + std::to_string(data.groups.front().excluded) + " without a participant left out" +
         video_count(data.video) + "), " + std::to_string(data.skipped.size()) +
         " skipped. Definitions of every measure: docs/report.md.\n\n";

  // The SEAN-EP rates per group.
  out += "## Overview (% of sessions)\n\n";
  Row header = {"group", "N", "left out"};
  for (const Rate& r : summary_rates()) header.push_back("% " + r.meaning);
  std::vector<Row> rows;
  for (const GroupSummary& g : data.groups) {
    Row row = {markdown_group_name(g), std::to_string(g.sessions), std::to_string(g.excluded)};
    for (const double pct : g.rate_percent) row.push_back(format_fixed(pct, 1));
    rows.push_back(row);
  }
  // The paper's own figures, for comparison, where it gives one.
  Row paper = {"SEAN-EP paper", std::to_string(kSeanSessions), ""};
  for (const Rate& r : summary_rates()) paper.push_back(r.paper_percent ? format_number(*r.paper_percent, 2) : "");
  rows.push_back(paper);
  markdown_table(out, header, rows);
  out += std::string(kPaperRowNote) + "\n\n";

  // Mean and median of each measure, one table per group.
  out += "## Measures (mean and median over the sessions that have a value)\n\n";
  for (const GroupSummary& g : data.groups) {
    out += "### " + markdown_group_name(g) + "\n\n";
    rows.clear();
    for (std::size_t i = 0; i < summarized_columns().size(); ++i) {
      const Column& c = session_column(summarized_columns()[i]);
      const Statistic& s = g.statistics[i];
      rows.push_back({c.name, c.unit, std::to_string(s.n), optional_cell(s.mean), optional_cell(s.median)});
    }
    markdown_table(out, {"measure", "unit", "N", "mean", "median"}, rows);
  }

  out += "## Sessions\n\n";
  header.clear();
  for (const Column& c : session_columns()) {
    if (c.shown) header.push_back(with_unit(c));
  }
  rows.clear();
  for (const SessionMetrics& m : data.sessions) {
    Row row;
    for (const Column& c : session_columns()) {
      if (!c.shown) continue;
      // Text comes from the data and is escaped; numbers and flags are ours.
      const Value value = c.value(m);
      const bool text = std::holds_alternative<std::string>(value);
      row.push_back(text ? markdown_escape(display_cell(value)) : display_cell(value));
    }
    rows.push_back(row);
  }
  markdown_table(out, header, rows);
  out += "Every column, unrounded: sessions.csv.\n\n";

  if (data.video.watchers > 0) {
    out += "## Video condition: " + std::to_string(data.video.pairs.size()) + " pairs\n\n" +
           markdown_escape(video_note(data.video)) + "\n\n";
  }
  if (!data.video.pairs.empty()) {
    header.clear();
    for (const PairColumn& c : pair_columns()) {
      if (c.shown) header.push_back(c.unit.empty() ? c.name : c.name + " (" + c.unit + ")");
    }
    rows.clear();
    for (const VideoPair& p : data.video.pairs) {
      Row row;
      for (const PairColumn& c : pair_columns()) {
        if (!c.shown) continue;
        const Value value = pair_cell(c, p, data.sessions);
        const bool text = std::holds_alternative<std::string>(value);
        row.push_back(text ? markdown_escape(display_cell(value)) : display_cell(value));
      }
      rows.push_back(row);
    }
    markdown_table(out, header, rows);
    out += "Every column, the source's measures included: pairs.csv.\n\n";
  }

  // A uid on two hosts: said whenever the report spans hosts, so that "none" is a finding too.
  if (!data.duplicates.empty() || host_count(data.sessions) > 1) {
    out += "## Duplicate participants\n\n";
    if (data.duplicates.empty()) {
      out += "No uid has sessions on more than one host (" + std::to_string(host_count(data.sessions)) + " hosts).\n\n";
    } else {
      out += markdown_escape(kDuplicatesNote) + "\n\n";
      rows.clear();
      for (const DuplicateUid& d : data.duplicates) {
        rows.push_back({markdown_escape(d.uid), escaped_list(d.hosts), escaped_list(d.folders)});
      }
      markdown_table(out, {"uid", "hosts", "sessions"}, rows);
    }
  }

  if (!data.repeats.empty()) {
    out += "## Sessions found twice\n\nEach was reported once, from the first folder found.\n\n";
    rows.clear();
    for (const RepeatedFolder& r : data.repeats) {
      rows.push_back({markdown_escape(r.folder), markdown_escape(r.same_as), markdown_escape(r.why)});
    }
    markdown_table(out, {"left out", "reported", "why the same"}, rows);
  }

  if (!data.exclusions.empty()) {
    out += "## Left out of the statistics\n\n";
    out += "Sessions nobody took part in: sim_manager's manager.json says no picture ever reached a participant's "
           "browser (the link was never spent). They are in the session table (link\\_spent no) and in sessions.csv "
           "(in\\_statistics 0), not in the overview or the measures.\n\n";
    rows.clear();
    for (const Exclusion& e : data.exclusions) rows.push_back({markdown_escape(e.reason), std::to_string(e.sessions)});
    markdown_table(out, {"why", "sessions"}, rows);
  }

  if (!data.skipped.empty()) {
    out += "## Skipped sessions\n\n";
    rows.clear();
    for (const SkippedSession& s : data.skipped) rows.push_back({markdown_escape(s.folder), markdown_escape(s.reason)});
    markdown_table(out, {"folder", "reason"}, rows);
  }

  if (!data.warnings.empty()) {
    out += "## Warnings\n\n";
    for (const std::string& w : data.warnings) out += "- " + markdown_escape(w) + "\n";
    out += "\n";
  }
  return out;
}

}  // namespace rfbsim::report
