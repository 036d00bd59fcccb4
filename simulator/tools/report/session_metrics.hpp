// SPDX-License-Identifier: GPL-2.0-or-later
// SessionMetrics: everything sim_report says about one session: who and what, the SEAN-EP study's
// measures of the participant and the robot (docs/sources.md), and the robot's social-navigation measures.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "record/session_log.hpp"
#include "robot/social_metrics.hpp"
#include "robot_metrics.hpp"
#include "session_samples.hpp"

namespace rfbsim::report {

/// Distances the SEAN-EP paper counted the robot as "within" the avatar at: its figures come from ROS logs
/// of poses, so centre to centre; sim_report applies them to the surface gap too (docs/sources.md).
constexpr double kSeanIntimate = 0.45;  // m
constexpr double kSeanPersonal = 1.2;   // m
/// An avatar that walked less than this over the whole session never moved.
constexpr double kNeverMovedPath = 0.1;  // m

/// What a watcher's session (the video condition) adds to its row: whose session it watched, and how much of it.
struct WatcherMetrics {
  std::optional<std::int64_t> yoked_to;  ///< the source's session id on the same host; none when run by hand
  std::string yoked_to_uid_hash;         ///< keyed hash of the source's uid (hex); "" when unknown
  std::string source_started_at;         ///< the source's started_at as the watcher's replay_of says
  std::optional<std::uint64_t> source_end_tick;  ///< the recording's length in ticks (replay_of.end_tick)
  std::optional<std::uint64_t> end_tick;         ///< the recording's tick reached when the watching ended
  std::optional<double> watched_s;  ///< s, ended_at - started_at of the watcher's session.json; none unended
  std::int64_t viewers = 0;         ///< viewer connections that came
};

/// One session's row of the report.
struct SessionMetrics {
  // Who and what.
  std::string folder;  ///< the session folder relative to the data folder (set by the caller)
  /// The host that ran it: manager.json's `host`, else the one its folder's place names (set by the caller;
  /// tools::host_from_layout).
  std::string host;
  bool duplicate_uid = false;  ///< its uid has sessions on more than one host (flag_duplicate_uids)
  /// The session's id on its host: manager.json's `id`, else the `<id>` of an `<id>-<uid>` folder name.
  std::optional<std::int64_t> session_id;
  std::string uid, scenario, scenario_file, seed;
  std::string started_at;  ///< session.json's, ISO 8601 UTC (a watcher's source is told by it)
  /// A watcher's session (condition video): none for an interactive one. A watcher walked nowhere, so its
  /// measures below are left at their defaults and its row's measure columns are empty.
  std::optional<WatcherMetrics> watcher;
  [[nodiscard]] bool video() const { return watcher.has_value(); }
  std::string outcome;     ///< completed, timeout, watched (a watcher shown the whole recording) or "" (none)
  std::string end_reason;  ///< completed, timeout, watched, signal, error or "" (did not end cleanly)
  bool ended_cleanly = false;  ///< session.json has ended_at
  double duration = 0.0;       ///< s: end_tick / tick_hz, else the last sample's time
  /// s: what the measures below cover: from the task clock's start (the participant's first picture; else
  /// the first viewer; else the world's start) to the outcome (else the end). Before it the participant's
  /// page was still loading; after it came only the grace period.
  double measured_from = 0.0;
  double measured_to = 0.0;
  std::size_t samples = 0;          ///< whole trajectory samples used
  std::size_t partial_samples = 0;  ///< sample ticks left out (someone's row missing or repeated)
  std::size_t torn_lines = 0;       ///< unfinished last lines dropped

  // Whether the recording is whole: session.json's data_incomplete, else the reason manager.json gives.
  std::string data_incomplete;      ///< why the files end early (a full disk...); "" when they are whole
  std::uint64_t dropped_bytes = 0;  ///< bytes sim_rfb dropped after the failure (session.json's count)

  // What sim_manager's manager.json says (add_manager_record); all empty without one (a session run by hand).
  bool has_manager_record = false;
  std::string manager_state;   ///< the manager's state: finished, expired, ..., abandoned
  std::string manager_detail;  ///< the manager's words on it
  bool link_spent = false;     ///< the session's first picture reached the participant's browser
  std::optional<double> link_spent_after;  ///< s from the manager creating the session to that picture

  // The SEAN-EP study's measures.
  bool timed_out = false;    ///< outcome is timeout
  bool completed = false;    ///< outcome is completed
  double avatar_path_length = 0.0;  ///< m
  bool never_moved = false;  ///< avatar_path_length < 0.1 m
  bool found_robot = false;  ///< a task event: event done, task find_robot
  bool has_robot = false;    ///< session.json lists a robot
  double avatar_radius = 0.0;                ///< m, the avatar's body radius as session.json records it
  std::optional<double> robot_radius;        ///< m, the robot's, as session.json records it; none without one
  std::optional<double> min_robot_avatar_distance;  ///< m, centres; none without robot samples
  bool robot_within_0_45 = false;  ///< min_robot_avatar_distance < 0.45 m (the paper's measure)
  bool robot_within_1_2 = false;   ///< min_robot_avatar_distance < 1.2 m (the paper's measure)
  /// m, the closest surfaces came: min_robot_avatar_distance - avatar_radius - robot_radius (negative
  /// while the bodies overlap); none without robot samples.
  std::optional<double> min_robot_avatar_gap;
  bool robot_gap_within_0_45 = false;  ///< min_robot_avatar_gap < 0.45 m
  bool robot_gap_within_1_2 = false;   ///< min_robot_avatar_gap < 1.2 m
  int avatar_robot_contacts = 0;     ///< contact events between the avatar and the robot
  bool avatar_pushed_robot = false;  ///< avatar_robot_contacts > 0
  int avatar_person_collisions = 0;  ///< contact events between the avatar and a person

  // The robot's social-navigation measures; none without a robot or samples.
  std::optional<RobotMetrics> robot;
  /// bench_nav's measures of the robot's own behaviour (social_measures: who caused each intrusion, its
  /// closest approach while moving toward someone, time to collision, path irregularity, time stopped);
  /// none without a robot or samples.
  std::optional<sim::SocialMetrics> social;
  std::optional<double> time_to_goal;  ///< s from measured_from: the first robot event with state arrived
};

/// Computes a session's metrics from its log and its samples (assemble_samples(log)).
SessionMetrics session_metrics(const sim::SessionLog& log, const SampledSession& samples);

}  // namespace rfbsim::report
