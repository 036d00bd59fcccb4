// SPDX-License-Identifier: GPL-2.0-or-later
// The report job over a data folder of several hand-made sessions: the overall and per-scenario figures,
// the CSV columns, a broken session skipped and named while the others are reported, hostile uids escaped
// in every format, and the scenario's walls drawn when its file loads.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "group_summary.hpp"
#include "record/digest.hpp"
#include "report_csv.hpp"
#include "report_job.hpp"
#include "session_files.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

// A session whose robot drives `length` m along +x at 0.5 m/s, with the avatar standing `offset` m to
// the side of its start and walking `walk` m along +y in the first second.
SessionSpec line_session(const std::string& uid, const std::string& scenario, double length, double offset,
                         double walk) {
  SessionSpec spec;
  spec.uid = uid;
  spec.scenario = scenario;
  spec.samples = static_cast<int>(std::lround(length / 0.05)) + 1;
  spec.tracks = {
      {"avatar", 0, 0.3, [=](double t) { return State{0, offset + walk * std::min(t, 1.0), 0, 0, 0}; }},
      {"robot", 0, 0.16, [](double t) { return State{0.5 * t, 0, 0, 0.5, 0}; }},
  };
  spec.end_tick = static_cast<std::uint64_t>(spec.samples - 1) * 6;
  spec.events = {event(0, "session", {{"event", "start"}})};
  return spec;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  return std::stod(row.at(column));
}

}  // namespace

TEST_CASE("the overall and per-scenario tables give the rates and statistics of the sessions") {
  ScratchDir scratch;
  const auto sessions = scratch.path() / "data" / "sessions";
  // lab: robot paths 2, 4 and 6 m; one timed out, one had the robot within 0.45 m, one never moved.
  SessionSpec a = line_session("a", "lab", 2.0, 0.4, 1.0);  // starts 0.4 m from the robot
  a.outcome = "timeout";
  write_session(sessions / "1-a", a);
  write_session(sessions / "2-b", line_session("b", "lab", 4.0, 1.0, 0.0));  // never moved, within 1.2 m
  SessionSpec c = line_session("c", "lab", 6.0, 2.0, 1.0);
  c.outcome = "completed";
  c.events.push_back(
      event(6, "contact", {{"a", "avatar"}, {"a_id", 0}, {"b", "robot"}, {"b_id", 0}, {"impulse", 1.0}}));
  write_session(sessions / "3-c", c);
  // warehouse: one session, robot path 1 m.
  write_session(sessions / "4-d", line_session("d", "warehouse", 1.0, 3.0, 1.0));

  const auto out = scratch.path() / "out";
  const JobResult result = run_report(scratch.path() / "data", out);
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_reported == 4);
  CHECK(result.written.size() == 5);  // sessions.csv, summary.csv, pairs.csv, report.md, report.html

  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 4);
  CHECK(row_of(rows, "a").at("folder") == "sessions/1-a");
  CHECK(row_of(rows, "a").at("timed_out") == "1");
  CHECK(row_of(rows, "a").at("robot_within_0_45") == "1");
  CHECK(number(row_of(rows, "a"), "min_robot_avatar_distance") == Approx(0.4));
  // The gap between the bodies, with the radii the sessions recorded (avatar 0.3 m, robot 0.16 m).
  CHECK(number(row_of(rows, "a"), "avatar_radius") == Approx(0.3));
  CHECK(number(row_of(rows, "a"), "robot_radius") == Approx(0.16));
  CHECK(number(row_of(rows, "a"), "min_robot_avatar_gap") == Approx(0.4 - 0.3 - 0.16));
  CHECK(row_of(rows, "a").at("robot_gap_within_0_45") == "1");
  CHECK(number(row_of(rows, "b"), "min_robot_avatar_gap") == Approx(1.0 - 0.46));
  CHECK(row_of(rows, "b").at("robot_gap_within_0_45") == "0");
  CHECK(row_of(rows, "b").at("robot_gap_within_1_2") == "1");
  CHECK(row_of(rows, "c").at("robot_gap_within_1_2") == "0");  // 2 m apart: a gap of 1.54 m
  CHECK(row_of(rows, "b").at("never_moved") == "1");
  CHECK(row_of(rows, "b").at("robot_within_1_2") == "1");
  CHECK(row_of(rows, "b").at("robot_within_0_45") == "0");
  CHECK(row_of(rows, "c").at("avatar_pushed_robot") == "1");
  CHECK(number(row_of(rows, "c"), "robot_path_length") == Approx(6.0));
  CHECK(number(row_of(rows, "c"), "duration") == Approx(12.0));
  CHECK(row_of(rows, "c").at("robot_time_to_goal").empty());

  // summary.csv: all four, then lab (3) and warehouse (1).
  const auto groups = csv_records(read_text(out / "summary.csv"));
  REQUIRE(groups.size() == 3);
  const auto& all = groups[0];
  CHECK(all.at("scope") == "all");
  CHECK(all.at("sessions") == "4");
  CHECK(number(all, "pct_timed_out") == Approx(25.0));
  CHECK(number(all, "pct_completed") == Approx(25.0));
  CHECK(number(all, "pct_never_moved") == Approx(25.0));
  CHECK(number(all, "pct_robot_within_0_45") == Approx(25.0));
  CHECK(number(all, "pct_robot_within_1_2") == Approx(50.0));
  CHECK(number(all, "pct_robot_gap_within_0_45") == Approx(25.0));  // a only: b's gap is 0.54 m
  CHECK(number(all, "pct_robot_gap_within_1_2") == Approx(50.0));
  CHECK(number(all, "min_robot_avatar_gap_mean") == Approx((-0.06 + 0.54 + 1.54 + 2.54) / 4));
  CHECK(number(all, "pct_avatar_pushed_robot") == Approx(25.0));
  CHECK(number(all, "robot_path_length_n") == 4);
  CHECK(number(all, "robot_path_length_mean") == Approx((2.0 + 4.0 + 6.0 + 1.0) / 4));
  CHECK(number(all, "robot_path_length_median") == Approx((2.0 + 4.0) / 2));
  CHECK(all.at("robot_time_to_goal_n") == "0");
  CHECK(all.at("robot_time_to_goal_mean").empty());
  const auto& lab = groups[1];
  CHECK(lab.at("scope") == "scenario");
  CHECK(lab.at("scenario") == "lab");
  CHECK(lab.at("sessions") == "3");
  CHECK(number(lab, "pct_timed_out") == Approx(100.0 / 3));
  CHECK(number(lab, "robot_path_length_mean") == Approx(4.0));
  CHECK(number(lab, "robot_path_length_median") == Approx(4.0));
  CHECK(number(lab, "robot_mean_speed_mean") == Approx(0.5));
  CHECK(groups[2].at("scenario") == "warehouse");
  CHECK(number(groups[2], "pct_never_moved") == Approx(0.0));
  CHECK(number(groups[2], "robot_path_length_median") == Approx(1.0));

  // report.md and report.html carry the same groups.
  const std::string md = read_text(out / "report.md");
  CHECK_THAT(md, Catch::Contains("| scenario lab | 3 | 0 | 33.3 |"));
  // The paper's figures under the groups, in the columns of the rates they compare with.
  CHECK_THAT(md, Catch::Contains("| SEAN-EP paper | 372 |  | 6.18 |  | 2.15 |  | 52.4 | 84.9 |  |  |  |  |  |\n"));
  const std::string html = read_text(out / "report.html");
  CHECK_THAT(html, Catch::Contains("<td>scenario warehouse</td>"));
  CHECK_THAT(html, Catch::Contains("<svg"));
}

TEST_CASE("a broken session among good ones is skipped and named, and the others are reported") {
  ScratchDir scratch;
  const auto data = scratch.path();
  write_session(data / "sessions" / "1-good", small_session());
  write_session(data / "sessions" / "2-broken", small_session());
  write_text(data / "sessions" / "2-broken" / "trajectories.csv", "tick,time,kind,id,x,y,yaw,vx,vy\n0,zero,avatar\n");
  write_session(data / "sessions" / "3-good", small_session());

  const JobResult result = run_report(data, data / "report");
  CHECK(result.exit_status() == 1);
  CHECK(result.sessions_found == 3);
  CHECK(result.sessions_reported == 2);
  REQUIRE(result.skipped.size() == 1);
  CHECK(result.skipped[0].folder == "sessions/2-broken");
  CHECK_THAT(result.skipped[0].reason, Catch::Contains("trajectories.csv:2: expected 9 columns"));

  const auto rows = csv_records(read_text(data / "report" / "sessions.csv"));
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("folder") == "sessions/1-good");
  CHECK(rows[1].at("folder") == "sessions/3-good");
  CHECK_THAT(read_text(data / "report" / "report.md"), Catch::Contains("sessions\\/2\\-broken"));
  CHECK_THAT(read_text(data / "report" / "report.html"), Catch::Contains("<td>sessions/2-broken</td>"));
}

TEST_CASE("a hostile uid is escaped in the HTML, the Markdown and the CSV") {
  ScratchDir scratch;
  SessionSpec spec = small_session();
  spec.uid = "<script>alert(\"x\")</script>,|*a*|&amp;";
  spec.scenario = "<img src=x onerror=alert(1)>";
  write_session(scratch.path() / "s1", spec);

  const JobResult result = run_report(scratch.path(), scratch.path() / "report");
  REQUIRE(result.sessions_reported == 1);
  const std::string html = read_text(scratch.path() / "report" / "report.html");
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("<img") == std::string::npos);
  CHECK_THAT(html, Catch::Contains("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;,|*a*|&amp;amp;"));
  CHECK_THAT(html, Catch::Contains("default-src 'none'"));  // and should anything slip through, no scripts run

  const std::string md = read_text(scratch.path() / "report" / "report.md");
  // Every '<' in the Markdown is escaped (report.md has none of its own).
  for (std::size_t at = md.find('<'); at != std::string::npos; at = md.find('<', at + 1)) {
    CHECK((at > 0 && md[at - 1] == '\\'));
  }
  CHECK_THAT(md, Catch::Contains("\\<script\\>alert\\(\\\"x\\\"\\)\\<\\/script\\>\\,\\|\\*a\\*\\|\\&amp\\;"));

  const auto rows = csv_records(read_text(scratch.path() / "report" / "sessions.csv"));
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].at("uid") == spec.uid);
  CHECK(rows[0].at("scenario") == spec.scenario);
}

TEST_CASE("the trajectory plot draws the scenario's walls when its file loads, and says so when it does not") {
  ScratchDir scratch;
  SessionSpec with_map = small_session();
  with_map.scenario_file = std::string(RFBSIM_SCENARIO_DIR) + "/lab.yaml";
  // The first session ran from the file as it is now, the second from an older version of it.
  auto doc = session_json(with_map);
  doc["versions"]["scenario_sha256"] = rfbsim::sim::sha256_file(with_map.scenario_file);
  write_session(scratch.path() / "1-lab", with_map);
  write_text(scratch.path() / "1-lab" / "session.json", doc.dump());
  doc["versions"]["scenario_sha256"] = std::string(64, '0');
  write_session(scratch.path() / "2-lab-again", with_map);
  write_text(scratch.path() / "2-lab-again" / "session.json", doc.dump());
  SessionSpec without = small_session();
  without.scenario_file = (scratch.path() / "gone.yaml").string();
  write_session(scratch.path() / "3-gone", without);

  REQUIRE(run_report(scratch.path(), scratch.path() / "report").sessions_reported == 3);
  const std::string html = read_text(scratch.path() / "report" / "report.html");
  // One map definition, used by both lab sessions.
  CHECK(html.find("<g id=\"map-0\">") != std::string::npos);
  CHECK(html.find("<g id=\"map-1\">") == std::string::npos);
  const auto uses = [&](const std::string& what) {
    std::size_t n = 0;
    for (auto at = html.find(what); at != std::string::npos; at = html.find(what, at + 1)) ++n;
    return n;
  };
  CHECK(uses("<use href=\"#map-0\"/>") == 2);
  CHECK(uses("<polygon") > 10);  // the lab's walls and desks
  CHECK(uses("<polyline") == 3 * 3);
  CHECK_THAT(html, Catch::Contains("Walls and props from " + with_map.scenario_file));
  CHECK_THAT(html, Catch::Contains("Drawn without walls: the scenario file could not be loaded"));
  CHECK(uses("SHA-256 differs") == 1);  // the older version's session only
}

TEST_CASE("an empty data folder is a data error, and the empty report is still written") {
  ScratchDir scratch;
  const JobResult result = run_report(scratch.path(), scratch.path() / "report");
  CHECK(result.sessions_found == 0);
  CHECK(result.exit_status() == 1);
  const auto groups = csv_records(read_text(scratch.path() / "report" / "summary.csv"));
  REQUIRE(groups.size() == 1);
  CHECK(groups[0].at("sessions") == "0");
  CHECK(read_text(scratch.path() / "report" / "sessions.csv").rfind("folder,uid,scenario,", 0) == 0);
}

TEST_CASE("the median is the middle value, or the mean of the two middle values") {
  CHECK(*statistic_of({3.0, 1.0, 2.0}).median == Approx(2.0));
  CHECK(*statistic_of({4.0, 1.0, 3.0, 2.0}).median == Approx(2.5));
  CHECK(*statistic_of({4.0, 1.0, 3.0, 2.0}).mean == Approx(2.5));
  CHECK_FALSE(statistic_of({}).mean.has_value());
  CHECK(statistic_of({}).n == 0);
}
