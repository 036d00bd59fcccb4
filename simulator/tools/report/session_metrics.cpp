// SPDX-License-Identifier: GPL-2.0-or-later
// SessionMetrics: session.json's facts, the events' counts and the samples' distances.
#include "session_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "social_measures.hpp"

namespace rfbsim::report {

namespace {

bool is_pair(const sim::Event& contact, const char* one, const char* other) {
  const std::string& a = contact.text("a");
  const std::string& b = contact.text("b");
  return (a == one && b == other) || (a == other && b == one);
}

// The ticks the measures cover: from the task clock's start (else the first viewer, else 0) to the outcome
// (else the end of the log).
struct Window {
  std::uint64_t from = 0;
  std::uint64_t to = std::numeric_limits<std::uint64_t>::max();
};

Window study_window(const sim::SessionLog& log) {
  Window window;
  std::optional<std::uint64_t> timer, first_viewer;
  for (const sim::Event& event : log.events) {
    if (event.type == "timer" && event.text("event") == "started" && !timer) timer = event.tick;
    if (event.type == "client" && event.text("event") == "connect" && !first_viewer) first_viewer = event.tick;
  }
  window.from = timer ? *timer : first_viewer.value_or(0);
  if (log.meta.completion) window.to = log.meta.completion->tick;
  return window;
}

SampledSession within(const SampledSession& all, const Window& window) {
  SampledSession kept = all;
  kept.samples.clear();
  for (const Sample& s : all.samples) {
    if (s.tick >= window.from && s.tick <= window.to) kept.samples.push_back(s);
  }
  return kept;
}

// What the events say: contacts, the find_robot step, the robot's arrival.
void count_events(const sim::SessionLog& log, const Window& window, double from_time, SessionMetrics& out) {
  for (const sim::Event& event : log.events) {
    if (event.tick < window.from || event.tick > window.to) continue;
    if (event.type == "contact") {
      if (is_pair(event, "avatar", "robot")) ++out.avatar_robot_contacts;
      if (is_pair(event, "avatar", "person")) ++out.avatar_person_collisions;
    } else if (event.type == "task") {
      if (event.text("event") == "done" && event.text("task") == "find_robot") out.found_robot = true;
    } else if (event.type == "robot") {
      if (event.text("state") == "arrived" && !out.time_to_goal) out.time_to_goal = event.time - from_time;
    }
  }
  out.avatar_pushed_robot = out.avatar_robot_contacts > 0;
}

// The avatar's walk and its closest approach to the robot, over the samples: centre to centre as the
// paper's pose logs gave it, and surface to surface with the radii the session recorded.
void measure_avatar(const SampledSession& samples, SessionMetrics& out) {
  double closest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < samples.samples.size(); ++i) {
    const Sample& s = samples.samples[i];
    if (i > 0) {
      const AgentState& before = samples.samples[i - 1].avatar;
      out.avatar_path_length += std::hypot(s.avatar.x - before.x, s.avatar.y - before.y);
    }
    if (s.robot) closest = std::min(closest, std::hypot(s.robot->x - s.avatar.x, s.robot->y - s.avatar.y));
  }
  out.never_moved = out.avatar_path_length < kNeverMovedPath;
  if (std::isfinite(closest)) {
    out.min_robot_avatar_distance = closest;
    out.robot_within_0_45 = closest < kSeanIntimate;
    out.robot_within_1_2 = closest < kSeanPersonal;
    const double gap = closest - samples.avatar_radius - samples.robot_radius;
    out.min_robot_avatar_gap = gap;
    out.robot_gap_within_0_45 = gap < kSeanIntimate;
    out.robot_gap_within_1_2 = gap < kSeanPersonal;
  }
}

}  // namespace

SessionMetrics session_metrics(const sim::SessionLog& log, const SampledSession& samples) {
  const sim::SessionMeta& meta = log.meta;
  SessionMetrics out;
  out.uid = meta.uid;
  out.scenario = meta.scenario;
  out.scenario_file = meta.scenario_file;
  out.seed = std::to_string(meta.seed);
  out.started_at = meta.started_at;
  out.outcome = meta.outcome.value_or("");
  out.end_reason = meta.end_reason.value_or("");
  out.ended_cleanly = meta.ended_at.has_value();
  if (meta.end_tick) {
    out.duration = static_cast<double>(*meta.end_tick) / meta.tick_hz;
  } else if (!log.trajectory.empty()) {
    out.duration = log.trajectory.back().time;
  }
  const Window window = study_window(log);
  const SampledSession measured = within(samples, window);
  out.measured_from = static_cast<double>(window.from) / meta.tick_hz;
  out.measured_to = window.to == std::numeric_limits<std::uint64_t>::max() ? out.duration
                                                                          : static_cast<double>(window.to) / meta.tick_hz;
  out.samples = measured.samples.size();
  out.partial_samples = samples.partial_samples;
  out.torn_lines = log.torn_lines;
  // A failure with no words for it is still a failure.
  if (meta.data_incomplete) out.data_incomplete = meta.data_incomplete->empty() ? "unknown" : *meta.data_incomplete;
  out.dropped_bytes = meta.dropped_bytes;

  out.timed_out = out.outcome == "timeout";
  out.completed = out.outcome == "completed";
  out.has_robot = samples.has_robot;
  out.avatar_radius = samples.avatar_radius;
  if (samples.has_robot) out.robot_radius = samples.robot_radius;
  count_events(log, window, out.measured_from, out);
  measure_avatar(measured, out);
  out.robot = robot_metrics(measured);
  out.social = social_measures(measured);
  return out;
}

}  // namespace rfbsim::report
