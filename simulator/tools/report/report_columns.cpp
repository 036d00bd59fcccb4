// SPDX-License-Identifier: GPL-2.0-or-later
// The columns of sessions.csv.
#include "report_columns.hpp"

#include <stdexcept>
#include <type_traits>
#include <utility>

#include "participation.hpp"
#include "text_format.hpp"

namespace rfbsim::report {

namespace {

using M = SessionMetrics;

Value count(std::size_t n) { return static_cast<std::int64_t>(n); }
Value count(int n) { return static_cast<std::int64_t>(n); }
Value maybe(const std::optional<double>& v) { return v ? Value(*v) : Value(); }

// A robot measure: empty without robot metrics.
template <typename Get>
std::function<Value(const M&)> robot(Get get) {
  return [get](const M& m) -> Value {
    if (!m.robot) return {};
    const auto v = get(*m.robot);
    if constexpr (std::is_same_v<decltype(v), const std::optional<double>>) {
      return maybe(v);
    } else if constexpr (std::is_same_v<decltype(v), const int>) {
      return count(v);
    } else {
      return Value(static_cast<double>(v));
    }
  };
}

// A social_metrics measure (bench_nav's): empty without a robot; `none` (a distance or time that never
// happened) is empty too, never the sentinel.
std::function<Value(const M&)> social_distance(double sim::SocialMetrics::*member) {
  return [member](const M& m) -> Value {
    if (!m.social) return {};
    const double v = (*m.social).*member;
    return v >= sim::SocialMetrics::kNoDistance ? Value() : Value(v);
  };
}

template <typename Get>
std::function<Value(const M&)> social(Get get) {
  return [get](const M& m) -> Value { return m.social ? get(*m.social) : Value(); };
}

Column column(const char* name, const char* unit, const char* meaning, std::function<Value(const M&)> value,
              bool summarized = false, bool shown = false) {
  return Column{name, unit, meaning, std::move(value), summarized, shown};
}

Value maybe_id(const std::optional<std::int64_t>& id) { return id ? Value(*id) : Value(); }

// Who and what: every session has these, a watcher's (the video condition) too.
std::vector<Column> who_columns() {
  // name, unit, meaning, value, summarized, shown
  return {
      column("folder", "", "session folder, relative to the data folder",
             [](const M& m) { return Value(m.folder); }, false, true),
      column("uid", "", "participant id from the link", [](const M& m) { return Value(m.uid); }, false, true),
      column("scenario", "", "scenario name", [](const M& m) { return Value(m.scenario); }, false, true),
      column("condition", "", "interactive (walked the scenario) or video (watched another's session)",
             [](const M& m) { return Value(std::string(m.video() ? "video" : "interactive")); }, false, true),
      column("yoked_to", "", "a watcher's source: the session_id it watched, on the same host; empty otherwise",
             [](const M& m) { return m.watcher ? maybe_id(m.watcher->yoked_to) : Value(); }, false, true),
      column("scenario_file", "", "scenario file the session was run from",
             [](const M& m) { return Value(m.scenario_file); }),
      column("seed", "", "master seed", [](const M& m) { return Value(m.seed); }),
      column("host", "", "host that ran it: manager.json's host, else the data folder's layout",
             [](const M& m) { return Value(m.host); }, false, true),
      column("session_id", "", "the session's id on its host (manager.json's id, else the folder's <id>-)",
             [](const M& m) { return maybe_id(m.session_id); }),
      column("duplicate_uid", "", "its uid also has a session on another host (drop it, or all of that uid's)",
             [](const M& m) { return Value(m.duplicate_uid); }, false, true),
      column("outcome", "", "completed, timeout, or empty", [](const M& m) { return Value(m.outcome); }, false, true),
      column("end_reason", "", "why it stopped; empty if it did not end cleanly",
             [](const M& m) { return Value(m.end_reason); }),
      column("ended_cleanly", "", "session.json has ended_at", [](const M& m) { return Value(m.ended_cleanly); }),
      column("manager_state", "", "sim_manager's state for it (manager.json); empty without one",
             [](const M& m) { return Value(m.manager_state); }, false, true),
      column("manager_detail", "", "sim_manager's words on that state",
             [](const M& m) { return Value(m.manager_detail); }),
      column("link_spent", "", "its first picture reached the participant's browser; empty without manager.json",
             [](const M& m) { return m.has_manager_record ? Value(m.link_spent) : Value(); }, false, true),
      column("link_spent_after", "s", "from the manager creating the session to that first picture",
             [](const M& m) { return maybe(m.link_spent_after); }, false, true),
      column("in_statistics", "", "counted in summary.csv; no when nobody took part (link never spent) or video",
             [](const M& m) { return Value(in_statistics(m)); }),
  };
}

}  // namespace

std::vector<Column> measure_columns() {
  // name, unit, meaning, value, summarized, shown
  std::vector<Column> columns = {
      column("duration", "s", "end_tick / tick_hz, else the last sample's time",
             [](const M& m) { return Value(m.duration); }, true, true),
      column("measured_from", "s", "start of what is measured: the task clock's start (first picture)",
             [](const M& m) { return Value(m.measured_from); }),
      column("measured_to", "s", "end of what is measured: the outcome, else the end",
             [](const M& m) { return Value(m.measured_to); }),
      column("samples", "", "whole trajectory samples used", [](const M& m) { return count(m.samples); }),
      column("partial_samples", "", "sample ticks left out: an agent's row missing or repeated",
             [](const M& m) { return count(m.partial_samples); }),
      column("torn_lines", "", "unfinished last lines dropped", [](const M& m) { return count(m.torn_lines); }),
      column("data_complete", "", "the recording is whole (no data_incomplete)",
             [](const M& m) { return Value(m.data_incomplete.empty()); }, false, true),
      column("data_incomplete", "", "why the recording stopped early (a full disk...); empty when whole",
             [](const M& m) { return Value(m.data_incomplete); }),
      column("dropped_bytes", "", "bytes of data dropped after that failure",
             [](const M& m) { return Value(static_cast<std::int64_t>(m.dropped_bytes)); }),
      column("timed_out", "", "outcome is timeout", [](const M& m) { return Value(m.timed_out); }),
      column("completed", "", "outcome is completed", [](const M& m) { return Value(m.completed); }),
      column("avatar_path_length", "m", "distance the avatar walked",
             [](const M& m) { return Value(m.avatar_path_length); }, true),
      column("never_moved", "", "avatar path length < 0.1 m",
             [](const M& m) { return Value(m.never_moved); }, false, true),
      column("found_robot", "", "the find_robot task step was done",
             [](const M& m) { return Value(m.found_robot); }, false, true),
      column("has_robot", "", "the session has a robot", [](const M& m) { return Value(m.has_robot); }),
      column("avatar_radius", "m", "the avatar's body radius (session.json)",
             [](const M& m) { return Value(m.avatar_radius); }),
      column("robot_radius", "m", "the robot's body radius (session.json)",
             [](const M& m) { return maybe(m.robot_radius); }),
      // The paper's measure (centres, as its pose logs gave them), then the same thresholds on the gap.
      column("min_robot_avatar_distance", "m", "closest robot-avatar centre distance",
             [](const M& m) { return maybe(m.min_robot_avatar_distance); }, true, true),
      column("robot_within_0_45", "", "robot ever < 0.45 m from the avatar (centres; SEAN-EP: 52.4 %)",
             [](const M& m) { return Value(m.robot_within_0_45); }, false, true),
      column("robot_within_1_2", "", "robot ever < 1.2 m from the avatar (centres; SEAN-EP: 84.9 %)",
             [](const M& m) { return Value(m.robot_within_1_2); }, false, true),
      column("min_robot_avatar_gap", "m", "closest robot-avatar surface gap: centre distance - both radii",
             [](const M& m) { return maybe(m.min_robot_avatar_gap); }, true, true),
      column("robot_gap_within_0_45", "", "robot's surface ever < 0.45 m from the avatar's",
             [](const M& m) { return Value(m.robot_gap_within_0_45); }, false, true),
      column("robot_gap_within_1_2", "", "robot's surface ever < 1.2 m from the avatar's",
             [](const M& m) { return Value(m.robot_gap_within_1_2); }, false, true),
      column("avatar_pushed_robot", "", "any avatar-robot contact event",
             [](const M& m) { return Value(m.avatar_pushed_robot); }),
      column("avatar_robot_contacts", "", "avatar-robot contact events",
             [](const M& m) { return count(m.avatar_robot_contacts); }, true, true),
      column("avatar_person_collisions", "", "avatar-person contact events",
             [](const M& m) { return count(m.avatar_person_collisions); }, true, true),
      column("robot_path_length", "m", "distance the robot travelled",
             robot([](const RobotMetrics& r) { return r.path_length; }), true, true),
      column("robot_path_ratio", "", "path length / straight start-end distance",
             robot([](const RobotMetrics& r) { return r.path_ratio; }), true),
      column("robot_heading_change", "rad", "sum of |heading change|",
             robot([](const RobotMetrics& r) { return r.heading_change; }), true),
      column("robot_min_person_distance", "m", "closest person or avatar (centres)",
             robot([](const RobotMetrics& r) { return r.min_person_distance; }), true, true),
      column("robot_mean_closest_distance", "m", "closest person's distance, mean over samples",
             robot([](const RobotMetrics& r) { return r.mean_closest_distance; }), true),
      column("robot_min_distance_approaching", "m", "closest person while the robot closed in faster",
             robot([](const RobotMetrics& r) { return r.min_distance_robot_approaching; }), true),
      column("robot_pct_intimate", "%", "samples with the closest person < 0.45 m",
             robot([](const RobotMetrics& r) { return r.pct_intimate; }), true),
      column("robot_pct_personal", "%", "samples with the closest person 0.45-1.2 m",
             robot([](const RobotMetrics& r) { return r.pct_personal; }), true),
      column("robot_pct_social", "%", "samples with the closest person 1.2-3.6 m",
             robot([](const RobotMetrics& r) { return r.pct_social; }), true),
      column("robot_pct_public", "%", "samples with the closest person >= 3.6 m",
             robot([](const RobotMetrics& r) { return r.pct_public; }), true),
      column("robot_collisions_robot_on_person", "", "collisions the robot closed faster",
             robot([](const RobotMetrics& r) { return r.robot_on_person; }), true, true),
      column("robot_collisions_person_on_robot", "", "collisions the person closed faster",
             robot([](const RobotMetrics& r) { return r.person_on_robot; }), true, true),
      column("robot_time_not_moving", "s", "time with robot speed < 0.01 m/s",
             robot([](const RobotMetrics& r) { return r.time_not_moving; }), true),
      column("robot_mean_speed", "m/s", "mean robot speed",
             robot([](const RobotMetrics& r) { return r.mean_speed; }), true),
      column("robot_mean_abs_acceleration", "m/s²", "mean |acceleration|",
             robot([](const RobotMetrics& r) { return r.mean_abs_acceleration; }), true),
      column("robot_mean_abs_jerk", "m/s³", "mean |jerk|",
             robot([](const RobotMetrics& r) { return r.mean_abs_jerk; }), true),
      column("robot_time_to_goal", "s", "time of the robot's first arrival",
             [](const M& m) { return maybe(m.time_to_goal); }, true, true),
      // bench_nav's measures of the robot's own doing (simulator/robot/social_metrics.hpp).
      column("robot_min_distance_moving_toward", "m", "closest person while the robot moved toward them",
             social_distance(&sim::SocialMetrics::min_distance_robot_approaching), true, true),
      column("robot_min_person_gap", "m", "closest surface gap to a person or the avatar",
             social_distance(&sim::SocialMetrics::min_gap), true),
      column("robot_personal_intrusions", "", "episodes of someone within 1.2 m of the robot (centres)",
             social([](const sim::SocialMetrics& s) { return count(s.personal_intrusions); }), true),
      column("robot_caused_personal_intrusions", "", "of those, the robot's doing",
             social([](const sim::SocialMetrics& s) { return count(s.robot_personal_intrusions); }), true, true),
      column("robot_intimate_intrusions", "", "episodes of someone within 0.45 m of the robot (centres)",
             social([](const sim::SocialMetrics& s) { return count(s.intimate_intrusions); }), true),
      column("robot_caused_intimate_intrusions", "", "of those, the robot's doing",
             social([](const sim::SocialMetrics& s) { return count(s.robot_intimate_intrusions); }), true, true),
      column("robot_intrusion_share", "%", "robot-caused share of the personal-space intrusions",
             social([](const sim::SocialMetrics& s) {
               return s.personal_intrusions > 0 ? Value(100.0 * s.robot_intrusion_share()) : Value();
             }),
             true),
      column("robot_min_ttc_moving_toward", "s", "least time to collision while the robot moved toward them",
             social([](const sim::SocialMetrics& s) {
               return s.min_ttc_robot_approaching >= sim::SocialMetrics::kNoTime ? Value()
                                                                                 : Value(s.min_ttc_robot_approaching);
             }),
             true),
      column("robot_path_irregularity_per_m", "rad/m", "heading turned beyond the straight line's, per metre",
             social([](const sim::SocialMetrics& s) { return Value(s.path_irregularity_per_m); }), true),
      column("robot_time_stopped", "s", "time with the robot slower than 0.01 m/s, sample to next sample",
             social([](const sim::SocialMetrics& s) { return Value(s.time_stopped); }), true),
  };
  // A watcher walked nowhere: none of these applies to its row (they are empty, never 0 or "no").
  for (Column& c : columns) {
    c.value = [value = std::move(c.value)](const M& m) { return m.video() ? Value() : value(m); };
  }
  return columns;
}

const std::vector<Column>& session_columns() {
  static const std::vector<Column> columns = [] {
    std::vector<Column> all = who_columns();
    for (Column& c : measure_columns()) all.push_back(std::move(c));
    return all;
  }();
  return columns;
}

const Column& session_column(const std::string& name) {
  for (const Column& c : session_columns()) {
    if (c.name == name) return c;
  }
  throw std::out_of_range("no sessions.csv column '" + name + "'");
}

std::string csv_cell(const Value& value) {
  if (const auto* text = std::get_if<std::string>(&value)) return csv_field(*text);
  if (const auto* number = std::get_if<double>(&value)) return format_number(*number, 6);
  if (const auto* n = std::get_if<std::int64_t>(&value)) return std::to_string(*n);
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? "1" : "0";
  return "";
}

std::string display_cell(const Value& value) {
  if (const auto* text = std::get_if<std::string>(&value)) return *text;
  if (const auto* number = std::get_if<double>(&value)) return format_fixed(*number, 3);
  if (const auto* n = std::get_if<std::int64_t>(&value)) return std::to_string(*n);
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? "yes" : "no";
  return "";
}

std::optional<double> numeric_value(const Value& value) {
  if (const auto* number = std::get_if<double>(&value)) return *number;
  if (const auto* n = std::get_if<std::int64_t>(&value)) return static_cast<double>(*n);
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? 1.0 : 0.0;
  return std::nullopt;
}

}  // namespace rfbsim::report
