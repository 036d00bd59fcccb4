// SPDX-License-Identifier: GPL-2.0-or-later
// Per-session metrics on hand-made sessions whose figures are known: a robot that turns in place, then
// drives a straight line past a standing avatar; a robot that drives into one person and is walked into by
// another. Expected values come from the tracks themselves, computed here, not from the report's code.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "measured_session.hpp"
#include "record/session_log.hpp"
#include "session_files.hpp"
#include "session_metrics.hpp"
#include "session_samples.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

// The robot stands still for 2 s turning in place from pi/2 to 0, then drives +x at 0.5 m/s for 10 s:
// from (0, 0) to (5, 0). The avatar stands 1 m to the side of the line's middle, at (2.5, 1); one person
// stands far away at (10, 10).
State passing_robot(double t) {
  if (t <= 2.0 + 1e-9) return {0.0, 0.0, kPi / 2 * (1.0 - t / 2.0), 0.0, 0.0};
  return {0.5 * (t - 2.0), 0.0, 0.0, 0.5, 0.0};
}

SessionSpec passing_session() {
  SessionSpec spec;
  spec.samples = 121;  // t = 0.0, 0.1, ..., 12.0
  spec.tracks = {standing("avatar", 0, 0.3, 2.5, 1.0), {"robot", 0, 0.16, passing_robot},
                 standing("person", 1, 0.25, 10.0, 10.0)};
  spec.outcome = "completed";
  spec.end_tick = 720;
  spec.events = {
      event(0, "session", {{"event", "start"}}),
      event(0, "robot", {{"state", "moving"}, {"detail", "following"}}),
      event(60, "task", {{"event", "done"}, {"index", 0}, {"task", "find_robot"}, {"text", "Find the robot"}}),
      event(300, "contact", {{"a", "robot"}, {"a_id", 0}, {"b", "avatar"}, {"b_id", 0}, {"impulse", 0.5}}),
      event(400, "contact", {{"a", "avatar"}, {"a_id", 0}, {"b", "robot"}, {"b_id", 0}, {"impulse", 0.5}}),
      event(410, "contact", {{"a", "avatar"}, {"a_id", 0}, {"b", "person"}, {"b_id", 1}, {"impulse", 0.2}}),
      event(420, "contact", {{"a", "person"}, {"a_id", 1}, {"b", "static"}, {"b_id", 0}, {"impulse", 0.2}}),
      event(690, "robot", {{"state", "arrived"}, {"detail", "goal reached"}}),
      event(700, "robot", {{"state", "arrived"}, {"detail", "again"}}),
  };
  return spec;
}

}  // namespace

TEST_CASE("a robot driving a straight line past a standing avatar gives the figures of its track") {
  ScratchDir scratch;
  const SessionMetrics m = measure(scratch, passing_session());

  // Session facts.
  CHECK(m.samples == 121);
  CHECK(m.partial_samples == 0);
  CHECK(m.duration == Approx(12.0));  // end_tick 720 at 60 Hz
  CHECK(m.completed);
  CHECK_FALSE(m.timed_out);
  CHECK(m.found_robot);
  CHECK(m.avatar_path_length == 0.0);
  CHECK(m.never_moved);
  CHECK(m.avatar_robot_contacts == 2);  // either order of a and b
  CHECK(m.avatar_pushed_robot);
  CHECK(m.avatar_person_collisions == 1);  // the person against a wall is not the avatar's
  REQUIRE(m.time_to_goal.has_value());
  CHECK(*m.time_to_goal == Approx(11.5));  // the first arrival, tick 690

  // The avatar is 1 m from the line: the robot passes it at exactly 1 m, inside 1.2 m but not 0.45 m.
  REQUIRE(m.min_robot_avatar_distance.has_value());
  CHECK(*m.min_robot_avatar_distance == Approx(1.0));
  CHECK(m.robot_within_1_2);
  CHECK_FALSE(m.robot_within_0_45);

  // The robot's measures, from the track: x = 0.05 k after the first 21 samples at x = 0.
  REQUIRE(m.robot.has_value());
  const RobotMetrics& r = *m.robot;
  CHECK(r.path_length == Approx(5.0));
  REQUIRE(r.path_ratio.has_value());
  CHECK(*r.path_ratio == Approx(1.0));
  CHECK(r.heading_change == Approx(kPi / 2));
  CHECK(r.min_person_distance == Approx(1.0));
  CHECK(r.time_not_moving == Approx(2.1));  // 21 samples standing, 0.1 s each
  CHECK(r.mean_speed == Approx(0.5 * 100 / 121));
  // Velocity steps 0 -> 0.5 m/s once in 120 intervals of 0.1 s: one acceleration of 5 m/s^2, and a jerk
  // of +50 then -50 m/s^3 among 119 second differences.
  REQUIRE(r.mean_abs_acceleration.has_value());
  CHECK(*r.mean_abs_acceleration == Approx(5.0 / 120));
  REQUIRE(r.mean_abs_jerk.has_value());
  CHECK(*r.mean_abs_jerk == Approx(100.0 / 119));
  CHECK(r.robot_on_person == 0);
  CHECK(r.person_on_robot == 0);

  // Distances and zones, counted sample by sample from the track. The avatar is always the closest.
  int intimate = 0, personal = 0, social = 0, public_zone = 0;
  double distance_sum = 0.0, approaching = 1e9;
  for (int k = 0; k <= 120; ++k) {
    const double x = k <= 20 ? 0.0 : 0.05 * (k - 20);
    const double d = std::hypot(x - 2.5, 1.0);
    distance_sum += d;
    (d < 0.45 ? intimate : d < 1.2 ? personal : d < 3.6 ? social : public_zone) += 1;
    if (k > 20 && x < 2.5) approaching = std::min(approaching, d);  // moving, and toward the avatar
  }
  CHECK(personal == 27);  // |x - 2.5| < sqrt(1.2^2 - 1) = 0.663 m: x = 1.85 ... 3.15
  CHECK(r.mean_closest_distance == Approx(distance_sum / 121));
  CHECK(r.pct_intimate == Approx(100.0 * intimate / 121).margin(1e-9));
  CHECK(r.pct_personal == Approx(100.0 * personal / 121));
  CHECK(r.pct_social == Approx(100.0 * social / 121));
  CHECK(r.pct_public == Approx(100.0 * public_zone / 121).margin(1e-9));
  REQUIRE(r.min_distance_robot_approaching.has_value());
  CHECK(*r.min_distance_robot_approaching == Approx(approaching));
  CHECK(approaching == Approx(std::sqrt(1.0025)));  // x = 2.45
}

TEST_CASE("collisions count once per touch, split by who was moving toward the other faster") {
  // The robot drives +x at 0.5 m/s through a standing person at (1, 0) and stops at (2, 0) after 4 s;
  // then a second person walks down at 1 m/s from (2, 3) and stops 0.4 m from the robot's centre.
  // Touching: centre distance - 0.16 - 0.25 < 0.02 m, i.e. closer than 0.43 m.
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 81;
  spec.tracks = {
      standing("avatar", 0, 0.3, 10.0, 10.0),
      {"robot", 0, 0.16, [](double t) { return t < 4.0 + 1e-9 ? State{0.5 * t, 0, 0, 0.5, 0} : State{2, 0, 0, 0, 0}; }},
      standing("person", 1, 0.25, 1.0, 0.0),
      {"person", 2, 0.25,
       [](double t) {
         if (t <= 4.0) return State{2, 3, 0, 0, 0};
         const double y = std::max(0.4, 3.0 - (t - 4.0));
         return State{2, y, -kPi / 2, 0, y > 0.4 + 1e-9 ? -1.0 : 0.0};
       }},
  };
  const SessionMetrics m = measure(scratch, spec);
  REQUIRE(m.robot.has_value());
  CHECK(m.robot->robot_on_person == 1);
  CHECK(m.robot->person_on_robot == 1);
  CHECK(m.robot->min_person_distance == Approx(0.0));  // the robot's centre passed through the first one
  CHECK(m.robot->pct_intimate > 0.0);
  CHECK_FALSE(m.completed);
  CHECK_FALSE(m.time_to_goal.has_value());
  CHECK(m.duration == Approx(8.0));  // no end_tick: the last sample's time
}

TEST_CASE("heading change wraps across plus and minus pi") {
  // Yaw 3.0 -> -3.0 -> 3.0 is two turns of 2 pi - 6 = 0.283 rad each, not of 6 rad.
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 3;
  spec.tracks = {standing("avatar", 0, 0.3, 5, 5),
                 {"robot", 0, 0.16, [](double t) { return State{0, 0, t > 0.05 && t < 0.15 ? -3.0 : 3.0, 0, 0}; }}};
  const SessionMetrics m = measure(scratch, spec);
  REQUIRE(m.robot.has_value());
  CHECK(m.robot->heading_change == Approx(2 * (2 * kPi - 6.0)));
  CHECK_FALSE(m.robot->path_ratio.has_value());  // it never left its spot
  CHECK(m.robot->time_not_moving == Approx(0.3));
  CHECK(m.robot->pct_public == Approx(100.0));  // the avatar is 7.07 m away
}

TEST_CASE("an avatar that walked 0.1 m or more moved, and a session without a robot has no robot measures") {
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 11;
  spec.tracks = {{"avatar", 0, 0.3, [](double t) { return State{t * 0.2, 0, 0, 0.2, 0}; }}};  // 0.2 m in 1 s
  const SessionMetrics m = measure(scratch, spec);
  CHECK(m.avatar_path_length == Approx(0.2));
  CHECK_FALSE(m.never_moved);
  CHECK_FALSE(m.has_robot);
  CHECK_FALSE(m.robot.has_value());
  CHECK_FALSE(m.min_robot_avatar_distance.has_value());
  CHECK_FALSE(m.robot_within_1_2);
}

TEST_CASE("a sample that lacks an agent's row is left out and counted") {
  ScratchDir scratch;
  SessionSpec spec = small_session();
  write_session(scratch.path(), spec);
  // A last sample cut after the avatar's row (the robot's and the person's rows never written).
  std::ofstream(scratch.path() / "trajectories.csv", std::ios::app) << "66,1.100000,avatar,0,1,1,0,0,0\n";
  const auto log = rfbsim::sim::read_session(scratch.path());
  const SampledSession samples = assemble_samples(log);
  CHECK(samples.samples.size() == 11);
  CHECK(samples.partial_samples == 1);
  CHECK(session_metrics(log, samples).partial_samples == 1);
}

TEST_CASE("only the session itself is measured: from the task clock's start to the outcome") {
  ScratchDir scratch;
  // The robot stands 0.3 m from the avatar while the page loads (t < 2 s) and again in the grace period
  // after the outcome (t > 10 s); in between it stands 5.5 m away.
  SessionSpec spec;
  spec.samples = 121;  // t = 0.0 .. 12.0
  spec.tracks = {standing("avatar", 0, 0.3, 2.5, 1.0),
                 {"robot", 0, 0.16, [](double t) {
                    return (t < 2.0 || t > 10.0 + 1e-9) ? State{2.5, 1.3, 0.0, 0.0, 0.0} : State{8.0, 1.0, 0.0, 0.0, 0.0};
                  }}};
  spec.outcome = "completed";
  spec.end_tick = 720;
  spec.events = {event(0, "session", {{"event", "start"}}),
                 event(60, "contact", {{"a", "avatar"}, {"a_id", 0}, {"b", "robot"}, {"b_id", 0}, {"impulse", 1.0}}),
                 event(150, "client", {{"event", "connect"}, {"client", 1}, {"address", "0123456789abcdef"}, {"websocket", true}}),
                 event(150, "timer", {{"event", "started"}}),
                 event(300, "contact", {{"a", "robot"}, {"a_id", 0}, {"b", "avatar"}, {"b_id", 0}, {"impulse", 1.0}}),
                 event(420, "robot", {{"state", "arrived"}, {"detail", "goal"}}),
                 event(600, "outcome", {{"outcome", "completed"}, {"code", "C1"}}),
                 event(660, "contact", {{"a", "avatar"}, {"a_id", 0}, {"b", "robot"}, {"b_id", 0}, {"impulse", 1.0}})};
  const auto dir = scratch.path() / "window";
  write_session(dir, spec);
  nlohmann::json session = nlohmann::json::parse(read_text(dir / "session.json"));
  session["completion"] = {{"code", "C1"}, {"tick", 600}, {"time", 10.0}};
  write_text(dir / "session.json", session.dump(2) + "\n");
  const rfbsim::sim::SessionLog log = rfbsim::sim::read_session(dir);
  const SessionMetrics m = session_metrics(log, assemble_samples(log));
  CHECK(m.measured_from == Approx(2.5));
  CHECK(m.measured_to == Approx(10.0));
  CHECK(m.samples == 76);  // ticks 150, 156, ..., 600
  REQUIRE(m.min_robot_avatar_distance);
  CHECK(*m.min_robot_avatar_distance == Approx(5.5));
  CHECK_FALSE(m.robot_within_0_45);
  CHECK_FALSE(m.robot_within_1_2);
  CHECK(m.avatar_robot_contacts == 1);
  REQUIRE(m.time_to_goal);
  CHECK(*m.time_to_goal == Approx(4.5));
  CHECK(m.duration == Approx(12.0));
}

TEST_CASE("the closest approach is given centre to centre and as the gap between the bodies' surfaces") {
  // The robot drives +x at 0.5 m/s along y = 0 past avatars standing beside the line; each case's avatar
  // stands `offset` m from it, so the closest centre distance is `offset` (at x = 2.5).
  struct Case {
    double offset;       // m: the closest centre distance
    double avatar;       // m: the avatar's radius as session.json records it
    bool centre_045, centre_12, gap_045, gap_12;
  };
  const Case cases[] = {
      {0.42, 0.25, true, true, true, true},     // touching bodies of 0.25 + 0.16: gap 0.01 m
      {0.60, 0.25, false, true, true, true},    // gap 0.19 m: within 0.45 m only between surfaces
      {1.00, 0.25, false, true, false, true},   // gap 0.59 m
      {1.50, 0.25, false, false, false, true},  // gap 1.09 m
      {2.00, 0.25, false, false, false, false},
      {0.46, 0.30, false, true, true, true},    // the old 0.3 m avatar touching: never within 0.45 m of centres
  };
  for (const Case& c : cases) {
    INFO("offset " << c.offset << ", avatar radius " << c.avatar);
    ScratchDir scratch;
    SessionSpec spec;
    spec.samples = 101;  // the robot from x = 0 to x = 5
    spec.tracks = {standing("avatar", 0, c.avatar, 2.5, c.offset),
                   {"robot", 0, 0.16, [](double t) { return State{0.5 * t, 0, 0, 0.5, 0}; }}};
    const SessionMetrics m = measure(scratch, spec);
    CHECK(m.avatar_radius == c.avatar);
    REQUIRE(m.robot_radius);
    CHECK(*m.robot_radius == 0.16);
    REQUIRE(m.min_robot_avatar_distance);
    CHECK(*m.min_robot_avatar_distance == Approx(c.offset));
    REQUIRE(m.min_robot_avatar_gap);
    CHECK(*m.min_robot_avatar_gap == Approx(c.offset - c.avatar - 0.16));
    CHECK(m.robot_within_0_45 == c.centre_045);
    CHECK(m.robot_within_1_2 == c.centre_12);
    CHECK(m.robot_gap_within_0_45 == c.gap_045);
    CHECK(m.robot_gap_within_1_2 == c.gap_12);
  }
}

TEST_CASE("overlapping bodies give a negative gap, and a session without a robot has neither measure") {
  ScratchDir scratch;
  SessionSpec spec;
  spec.samples = 3;
  spec.tracks = {standing("avatar", 0, 0.25, 1.0, 1.0), standing("robot", 0, 0.16, 1.4, 1.0)};
  const SessionMetrics m = measure(scratch, spec);
  REQUIRE(m.min_robot_avatar_gap);
  CHECK(*m.min_robot_avatar_gap == Approx(-0.01));
  CHECK(m.robot_gap_within_0_45);

  ScratchDir alone_dir;
  SessionSpec alone;
  alone.samples = 3;
  alone.tracks = {standing("avatar", 0, 0.25, 1.0, 1.0)};
  const SessionMetrics a = measure(alone_dir, alone);
  CHECK(a.avatar_radius == 0.25);
  CHECK_FALSE(a.robot_radius);
  CHECK_FALSE(a.min_robot_avatar_gap);
  CHECK_FALSE(a.robot_gap_within_0_45);
  CHECK_FALSE(a.robot_gap_within_1_2);
}
