// SPDX-License-Identifier: GPL-2.0-or-later
// The robot's social-navigation measures (social_metrics, as bench_nav takes them) from recorded sessions:
// a robot that drives up to a standing participant and stops 1.0 m short, people walking past a standing
// robot, a robot that weaves, a session without a robot, and a damaged time column. Expected values come
// from the tracks, worked out here by hand, not from the report's code.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <string>

#include "group_summary.hpp"
#include "measured_session.hpp"
#include "record/session_log.hpp"
#include "report_columns.hpp"
#include "report_job.hpp"
#include "session_files.hpp"
#include "session_metrics.hpp"
#include "session_samples.hpp"
#include "social_measures.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

constexpr double kTouch = 0.16 + 0.25;  // m: robot and body radii summed

// The robot starts at rest at (0, 0) facing +x, drives at 0.5 m/s straight at the participant's avatar
// standing at (5, 0) and stops at (4, 0), 1.0 m from its centre, at t = 8 s; it stands there until t = 12 s.
// A person stands far off at (0, 10).
SessionSpec approach_session() {
  SessionSpec spec;
  spec.uid = "approach";
  spec.samples = 121;  // t = 0.0 .. 12.0
  spec.tracks = {standing("avatar", 0, 0.25, 5.0, 0.0),
                 {"robot", 0, 0.16,
                  [](double t) {
                    if (t <= 8.0 + 1e-9) return State{0.5 * t, 0, 0, t > 1e-9 ? 0.5 : 0.0, 0};
                    return State{4.0, 0, 0, 0, 0};
                  }},
                 standing("person", 1, 0.25, 0.0, 10.0)};
  spec.end_tick = 720;
  spec.events = {event(0, "session", {{"event", "start"}})};
  return spec;
}

// The robot stands at (0, 0) for 10 s while two people walk past it at 1 m/s: person 1 along y = 0.8 from
// x = -5 to 5, person 2 along y = -0.44 from x = 5 to -5 (within 0.45 m only at x = 0). The avatar stands
// far off at (10, 10).
SessionSpec passers_by_session() {
  SessionSpec spec;
  spec.uid = "passers";
  spec.samples = 101;  // t = 0.0 .. 10.0
  spec.tracks = {standing("avatar", 0, 0.25, 10.0, 10.0), standing("robot", 0, 0.16, 0.0, 0.0),
                 {"person", 1, 0.25, [](double t) { return State{-5.0 + t, 0.8, 0, 1.0, 0}; }},
                 {"person", 2, 0.25, [](double t) { return State{5.0 - t, -0.44, kPi, -1.0, 0}; }}};
  spec.end_tick = 600;
  spec.events = {event(0, "session", {{"event", "start"}})};
  return spec;
}

std::string cell(const SessionMetrics& m, const std::string& column) {
  return csv_cell(session_column(column).value(m));
}

double number(const SessionMetrics& m, const std::string& column) {
  const auto v = numeric_value(session_column(column).value(m));
  if (!v) throw std::runtime_error("column " + column + " is empty");
  return *v;
}

// The columns that come from social_metrics.
const char* const kSocialColumns[] = {
    "robot_min_distance_moving_toward", "robot_min_person_gap",          "robot_personal_intrusions",
    "robot_caused_personal_intrusions", "robot_intimate_intrusions",     "robot_caused_intimate_intrusions",
    "robot_intrusion_share",            "robot_min_ttc_moving_toward",   "robot_path_irregularity_per_m",
    "robot_time_stopped"};

// The approach and passers-by sessions, as data/1-approach and data/2-passers.
void write_robot_social_sessions(const std::filesystem::path& data) {
  write_session(data / "1-approach", approach_session());
  write_session(data / "2-passers", passers_by_session());
}

// summary.csv's "all sessions" row over the approach and passers-by sessions: each statistic over the sessions
// that have a value (one intrusion in two sessions; one closing-in distance, 1.0 m).
void check_robot_social_summary(const std::filesystem::path& out) {
  const auto groups = csv_records(read_text(out / "summary.csv"));
  REQUIRE_FALSE(groups.empty());
  const auto& all = groups[0];
  CHECK(all.at("robot_caused_personal_intrusions_n") == "2");
  CHECK(std::stod(all.at("robot_caused_personal_intrusions_mean")) == Approx(0.5));
  CHECK(all.at("robot_min_distance_moving_toward_n") == "1");
  CHECK(std::stod(all.at("robot_min_distance_moving_toward_median")) == Approx(1.0));
  CHECK(std::stod(all.at("robot_intrusion_share_mean")) == Approx(50.0));
  CHECK(std::stod(all.at("pct_robot_caused_intimate")) == Approx(0.0));
}

const Rate& rate(const std::string& name) {
  for (const Rate& r : summary_rates()) {
    if (r.name == name) return r;
  }
  throw std::runtime_error("no rate " + name);
}

}  // namespace

TEST_CASE("a robot that drives at a standing participant and stops 1.0 m short intruded, and it was its doing") {
  ScratchDir scratch;
  const SessionMetrics m = measure(scratch, approach_session());
  REQUIRE(m.social.has_value());
  const rfbsim::sim::SocialMetrics& s = *m.social;

  // Its closest approach while moving toward the avatar is where it stopped: 1.0 m, as bench_nav's.
  CHECK(s.min_distance_robot_approaching == Approx(1.0));
  CHECK(number(m, "robot_min_distance_moving_toward") == Approx(1.0));
  // It crossed 1.2 m (at x = 3.85, t = 7.7 s) moving toward her and stayed: one personal-space intrusion,
  // the robot's; it never came within 0.45 m.
  CHECK(cell(m, "robot_personal_intrusions") == "1");
  CHECK(cell(m, "robot_caused_personal_intrusions") == "1");
  CHECK(cell(m, "robot_intimate_intrusions") == "0");
  CHECK(cell(m, "robot_caused_intimate_intrusions") == "0");
  CHECK(number(m, "robot_intrusion_share") == Approx(100.0));
  CHECK_FALSE(rate("robot_caused_intimate").holds(m));
  // Constant-velocity time to collision, least at the last moving sample: (1.0 - 0.41) m at 0.5 m/s.
  CHECK(number(m, "robot_min_ttc_moving_toward") == Approx((1.0 - kTouch) / 0.5));
  // Stopped: the interval after the first sample (at rest) and the 39 after t = 8.1 s.
  CHECK(number(m, "robot_time_stopped") == Approx(4.0));
  // A straight line with no turn: no irregularity.
  CHECK(number(m, "robot_path_irregularity_per_m") == Approx(0.0).margin(1e-12));
  CHECK(s.path_length == Approx(4.0));
  // The overall minimum, the participant included, is the same in both measure sets.
  CHECK(s.min_distance == Approx(1.0));
  REQUIRE(m.robot);
  CHECK(m.robot->min_person_distance == Approx(s.min_distance));
  CHECK(number(m, "robot_min_person_gap") == Approx(1.0 - kTouch));
}

TEST_CASE("people walking past a standing robot intrude on it, but the intrusions are not the robot's") {
  ScratchDir scratch;
  const SessionMetrics m = measure(scratch, passers_by_session());
  REQUIRE(m.social.has_value());
  // Person 1 is within 1.2 m while |x| < 0.894 m, person 2 while |x| < 1.116 m and within 0.45 m at x = 0.
  CHECK(cell(m, "robot_personal_intrusions") == "2");
  CHECK(cell(m, "robot_caused_personal_intrusions") == "0");
  CHECK(cell(m, "robot_intimate_intrusions") == "1");
  CHECK(cell(m, "robot_caused_intimate_intrusions") == "0");
  CHECK(number(m, "robot_intrusion_share") == Approx(0.0));
  CHECK_FALSE(rate("robot_caused_intimate").holds(m));
  // The robot never moved toward anyone: no such distance or time, and the cells are empty, not zero.
  CHECK(cell(m, "robot_min_distance_moving_toward").empty());
  CHECK(cell(m, "robot_min_ttc_moving_toward").empty());
  // Each passes beside it, more than the two radii off its centre: never on a collision course.
  CHECK(m.social->min_ttc == rfbsim::sim::SocialMetrics::kNoTime);
  CHECK(number(m, "robot_time_stopped") == Approx(10.0));
  CHECK(number(m, "robot_path_irregularity_per_m") == 0.0);
  CHECK(m.social->min_distance == Approx(0.44));
  CHECK(number(m, "robot_min_person_gap") == Approx(0.44 - kTouch));
}

TEST_CASE("path irregularity is the heading turned beyond the straight line's one turn, per metre") {
  // The robot turns in place from pi/2 to 0 in the first second (the turn the straight line needs), then at
  // 0.5 m/s drives 1 m along +x, 1 m at +0.5 rad, 1 m at -0.5 rad (back to y = 0) and 1 m along +x: it
  // turned 0.5 + 1.0 + 0.5 = 2 rad more than the line needed over 4 m.
  const double c = std::cos(0.5), s = std::sin(0.5);
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 91;  // t = 0.0 .. 9.0
  spec.tracks = {standing("avatar", 0, 0.25, 0.0, 10.0),
                 {"robot", 0, 0.16, [=](double t) {
                    if (t <= 1.0 + 1e-9) return State{0, 0, kPi / 2 * (1.0 - t), 0, 0};
                    if (t <= 3.0 + 1e-9) return State{0.5 * (t - 1), 0, 0, 0.5, 0};
                    if (t <= 5.0 + 1e-9) return State{1 + 0.5 * c * (t - 3), 0.5 * s * (t - 3), 0.5, 0.5 * c, 0.5 * s};
                    if (t <= 7.0 + 1e-9) {
                      return State{1 + c + 0.5 * c * (t - 5), s - 0.5 * s * (t - 5), -0.5, 0.5 * c, -0.5 * s};
                    }
                    return State{1 + 2 * c + 0.5 * (t - 7), 0, 0, 0.5, 0};
                  }}};
  const SessionMetrics m = measure(scratch, spec);
  REQUIRE(m.social.has_value());
  CHECK(m.social->path_length == Approx(4.0).margin(1e-5));
  CHECK(m.social->path_irregularity == Approx(2.0).margin(1e-5));
  CHECK(number(m, "robot_path_irregularity_per_m") == Approx(0.5).margin(1e-5));
  CHECK(number(m, "robot_time_stopped") == Approx(1.1));  // at rest up to and including t = 1.0 s
}

TEST_CASE("a session without a robot has empty social measures, not zeros") {
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 11;
  spec.tracks = {standing("avatar", 0, 0.25, 1.0, 1.0), standing("person", 1, 0.25, 1.5, 1.0)};
  const SessionMetrics m = measure(scratch, spec);
  CHECK_FALSE(m.social.has_value());
  for (const char* column : kSocialColumns) {
    INFO(column);
    CHECK(cell(m, column).empty());
  }
  CHECK_FALSE(rate("robot_caused_intimate").holds(m));
}

TEST_CASE("the series lists the people in session.json's order and the avatar last, with recorded bodies") {
  ScratchDir scratch;
  write_session(scratch.path(), passers_by_session());
  const auto log = rfbsim::sim::read_session(scratch.path());
  const SampledSession samples = assemble_samples(log);
  const auto series = social_series(samples);
  REQUIRE(series.size() == 101);
  const rfbsim::sim::SocialSample& middle = series[50];  // t = 5 s
  CHECK(middle.time == Approx(5.0));
  REQUIRE(middle.people.size() == 3);
  CHECK(middle.people[0].position.y() == Approx(0.8));
  CHECK(middle.people[0].velocity.x() == Approx(1.0));
  CHECK(middle.people[1].position.y() == Approx(-0.44));
  CHECK(middle.people[2].position.x() == Approx(10.0));  // the avatar
  CHECK(middle.people[2].radius == 0.25);
  CHECK(social_params(samples).robot_radius == 0.16);
}

TEST_CASE("a time column that runs backwards is refused with the tick, and the report skips that session") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_session(data / "1-good", approach_session());
  write_session(data / "2-bad", approach_session());
  // Tick 12's rows say t = 0.05 s, before tick 6's 0.1 s; the ticks themselves stay in order.
  std::string csv = read_text(data / "2-bad" / "trajectories.csv");
  for (std::size_t at = csv.find("\n12,0.200000,"); at != std::string::npos; at = csv.find("\n12,0.200000,", at)) {
    csv.replace(at, 13, "\n12,0.050000,");
  }
  write_text(data / "2-bad" / "trajectories.csv", csv);
  const auto log = rfbsim::sim::read_session(data / "2-bad");
  CHECK_THROWS_WITH(session_metrics(log, assemble_samples(log)), Catch::Contains("tick 12"));

  const JobResult result = run_report(data, scratch.path() / "out");
  CHECK(result.sessions_reported == 1);
  REQUIRE(result.skipped.size() == 1);
  CHECK(result.skipped[0].folder == "2-bad");
  CHECK_THAT(result.skipped[0].reason, Catch::Contains("trajectories.csv") && Catch::Contains("tick 12"));
}

TEST_CASE("sessions.csv and summary.csv carry the social measures") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_robot_social_sessions(data);
  const auto out = scratch.path() / "out";
  REQUIRE(run_report(data, out).exit_status() == 0);

  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("robot_caused_personal_intrusions") == "1");
  CHECK(std::stod(rows[0].at("robot_min_distance_moving_toward")) == Approx(1.0));
  CHECK(rows[1].at("robot_caused_personal_intrusions") == "0");
  CHECK(rows[1].at("robot_min_distance_moving_toward").empty());

  // The group's statistics are over the sessions with a value.
  check_robot_social_summary(out);
}

TEST_CASE("sessions without a robot add no zeros to sessions.csv or summary.csv") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_robot_social_sessions(data);
  SessionSpec alone;
  alone.uid = "alone";
  alone.samples = 11;
  alone.tracks = {standing("avatar", 0, 0.25, 1.0, 1.0)};
  write_session(data / "3-alone", alone);
  const auto out = scratch.path() / "out";
  REQUIRE(run_report(data, out).exit_status() == 0);

  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 3);
  for (const char* column : kSocialColumns) {
    INFO(column);
    CHECK(rows[2].at(column).empty());
  }

  // The group's statistics are over the sessions with a value: the lone avatar's empties are not zeros.
  check_robot_social_summary(out);
}
