// SPDX-License-Identifier: GPL-2.0-or-later
// The report with sim_manager's manager.json: each session's state, spent link and data completeness in
// sessions.csv, sessions nobody saw left out of summary.csv and counted per reason, folders without a
// manager.json reported as before, and a broken or foreign manager.json a warning that names the file.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "report_job.hpp"
#include "session_files.hpp"
#include "text_format.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

// small_session() (11 samples, the avatar standing still: never moved) for `uid` in `scenario`; `walk` makes
// the avatar walk 1 m along +x in the first second instead.
SessionSpec session_of(const std::string& uid, const std::string& scenario, bool walk) {
  SessionSpec spec = small_session();
  spec.uid = uid;
  spec.scenario = scenario;
  if (walk) {
    spec.tracks[0].at = [](double t) { return State{1.0 + std::min(t, 1.0), 1.0, 0.0, 0.0, 0.0}; };
  }
  return spec;
}

}  // namespace

TEST_CASE("abandoned sessions are shown but left out of the statistics, and each session says if its link was spent") {
  ScratchDir scratch;
  const auto sessions = scratch.path() / "sessions";
  // lab: a walked (spent after 0.8 s), b never saw a picture (abandoned), c was run by hand (no manager.json),
  // e never moved and lost data after its link was spent (ENOSPC, 4096 bytes dropped).
  write_session(sessions / "1-a", session_of("a", "lab", true));
  write_text(sessions / "1-a" / "manager.json", manager_json("a", "finished", 800));
  write_session(sessions / "2-b", session_of("b", "lab", false));
  write_text(sessions / "2-b" / "manager.json", manager_json("b", "abandoned"));
  write_session(sessions / "3-c", session_of("c", "lab", false));
  SessionSpec e = session_of("e", "lab", false);
  e.data_incomplete = "write failed: No space left on device";
  e.dropped_bytes = 4096;
  write_session(sessions / "5-e", e);
  write_text(sessions / "5-e" / "manager.json", manager_json("e", "ended", 1250, "write failed"));
  // warehouse: d abandoned, f crashed before its first picture, g spent and the manager alone knew of a failure.
  write_session(sessions / "4-d", session_of("d", "warehouse", false));
  write_text(sessions / "4-d" / "manager.json", manager_json("d", "abandoned"));
  write_session(sessions / "6-f", session_of("f", "warehouse", false));
  write_text(sessions / "6-f" / "manager.json", manager_json("f", "crashed"));
  write_session(sessions / "7-g", session_of("g", "warehouse", true));
  write_text(sessions / "7-g" / "manager.json", manager_json("g", "expired", 2000, "ENOSPC"));

  const auto out = scratch.path() / "report";
  const JobResult result = run_report(scratch.path(), out);
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_reported == 7);
  CHECK(result.sessions_excluded == 3);
  CHECK(result.warnings.empty());

  // sessions.csv: every session, with what the manager said.
  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 7);
  const auto& a = row_of(rows, "a");
  CHECK(a.at("manager_state") == "finished");
  CHECK(a.at("link_spent") == "1");
  CHECK(a.at("link_spent_after") == "0.8");
  CHECK(a.at("in_statistics") == "1");
  CHECK(a.at("data_complete") == "1");
  CHECK(a.at("data_incomplete").empty());
  CHECK(a.at("dropped_bytes") == "0");
  const auto& b = row_of(rows, "b");
  CHECK(b.at("manager_state") == "abandoned");
  CHECK(b.at("manager_detail") == "no browser connected for 60 s");
  CHECK(b.at("link_spent") == "0");
  CHECK(b.at("link_spent_after").empty());
  CHECK(b.at("in_statistics") == "0");
  const auto& c = row_of(rows, "c");  // run by hand: nothing from the manager, and it counts
  CHECK(c.at("manager_state").empty());
  CHECK(c.at("link_spent").empty());
  CHECK(c.at("link_spent_after").empty());
  CHECK(c.at("in_statistics") == "1");
  const auto& row_e = row_of(rows, "e");  // session.json's own reason wins over the manager's
  CHECK(row_e.at("data_complete") == "0");
  CHECK(row_e.at("data_incomplete") == "write failed: No space left on device");
  CHECK(row_e.at("dropped_bytes") == "4096");
  CHECK(row_e.at("link_spent_after") == "1.25");
  CHECK(row_of(rows, "f").at("in_statistics") == "0");
  const auto& g = row_of(rows, "g");  // only the manager knew
  CHECK(g.at("data_complete") == "0");
  CHECK(g.at("data_incomplete") == "ENOSPC");
  CHECK(g.at("link_spent_after") == "2");

  // summary.csv: N counts the participants only; never moved is c and e of a, c, e (lab), and none of g.
  const auto groups = csv_records(read_text(out / "summary.csv"));
  REQUIRE(groups.size() == 3);
  CHECK(groups[0].at("scope") == "all");
  CHECK(groups[0].at("sessions") == "4");
  CHECK(groups[0].at("excluded_sessions") == "3");
  CHECK(std::stod(groups[0].at("pct_never_moved")) == Approx(50.0));
  CHECK(groups[0].at("duration_n") == "4");
  CHECK(groups[1].at("scenario") == "lab");
  CHECK(groups[1].at("sessions") == "3");
  CHECK(groups[1].at("excluded_sessions") == "1");
  CHECK(std::stod(groups[1].at("pct_never_moved")) == Approx(200.0 / 3));
  CHECK(groups[2].at("scenario") == "warehouse");
  CHECK(groups[2].at("sessions") == "1");
  CHECK(groups[2].at("excluded_sessions") == "2");
  CHECK(groups[2].at("pct_never_moved") == "0");
  CHECK(groups[2].at("avatar_path_length_n") == "1");
  CHECK(std::stod(groups[2].at("avatar_path_length_mean")) == Approx(1.0));

  // report.md and report.html: the counts, and why each was left out.
  const std::string md = read_text(out / "report.md");
  CHECK_THAT(md, Catch::Contains("7 sessions reported (4 in the statistics, 3 without a participant left out), "
                                 "0 skipped"));
  CHECK_THAT(md, Catch::Contains("| scenario warehouse | 1 | 2 | 0.0 |"));
  CHECK_THAT(md, Catch::Contains("## Left out of the statistics"));
  CHECK_THAT(md, Catch::Contains("| " + markdown_escape("abandoned: no picture ever reached a participant's browser") +
                                 " | 2 |"));
  CHECK_THAT(md, Catch::Contains("| " + markdown_escape("crashed before any picture reached a participant's browser") +
                                 " | 1 |"));
  const std::string html = read_text(out / "report.html");
  CHECK_THAT(html, Catch::Contains("<td>abandoned: no picture ever reached a participant&#39;s browser</td>"
                                   "<td class=\"n\">2</td>"));
  CHECK_THAT(html, Catch::Contains("<td>scenario lab</td><td class=\"n\">3</td><td class=\"n\">1</td>"));
}

TEST_CASE("a folder without manager.json is reported as before, with nothing left out") {
  ScratchDir scratch;
  write_session(scratch.path() / "1-a", session_of("a", "lab", false));
  const JobResult result = run_report(scratch.path(), scratch.path() / "report");
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_excluded == 0);
  const auto groups = csv_records(read_text(scratch.path() / "report" / "summary.csv"));
  CHECK(groups[0].at("sessions") == "1");
  CHECK(groups[0].at("excluded_sessions") == "0");
  CHECK(read_text(scratch.path() / "report" / "report.md").find("Left out") == std::string::npos);
}

TEST_CASE("a garbage or foreign manager.json is a warning naming the file, and the session is reported without it") {
  ScratchDir scratch;
  write_session(scratch.path() / "1-garbage", session_of("a", "lab", false));
  write_text(scratch.path() / "1-garbage" / "manager.json", std::string("\x01\xff{\"state\":", 11));
  write_session(scratch.path() / "2-foreign", session_of("b", "lab", false));
  write_text(scratch.path() / "2-foreign" / "manager.json", manager_json("<someone-else>", "abandoned"));
  write_session(scratch.path() / "3-good", session_of("c", "lab", false));
  write_text(scratch.path() / "3-good" / "manager.json", manager_json("c", "abandoned"));

  const JobResult result = run_report(scratch.path(), scratch.path() / "report");
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_reported == 3);
  CHECK(result.sessions_excluded == 1);
  REQUIRE(result.warnings.size() == 2);
  CHECK_THAT(result.warnings[0], Catch::StartsWith((scratch.path() / "1-garbage" / "manager.json").string() +
                                                   ": not JSON") &&
                                     Catch::EndsWith("; reported without it"));
  CHECK(result.warnings[1] == (scratch.path() / "2-foreign" / "manager.json").string() +
                                  ": uid '<someone-else>' is not session.json's 'b'; ignored");

  const auto rows = csv_records(read_text(scratch.path() / "report" / "sessions.csv"));
  REQUIRE(rows.size() == 3);
  CHECK(rows[0].at("manager_state").empty());
  CHECK(rows[0].at("in_statistics") == "1");
  CHECK(rows[1].at("manager_state").empty());
  CHECK(rows[2].at("in_statistics") == "0");
  CHECK_THAT(read_text(scratch.path() / "report" / "report.md"), Catch::Contains("## Warnings"));
  const std::string html = read_text(scratch.path() / "report" / "report.html");
  CHECK_THAT(html, Catch::Contains("uid &#39;&lt;someone-else&gt;&#39; is not session.json"));
  CHECK(html.find("<someone-else>") == std::string::npos);
}
