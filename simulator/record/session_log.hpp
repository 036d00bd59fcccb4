// SPDX-License-Identifier: GPL-2.0-or-later
// SessionLog: one session's data folder read back and checked against docs/data.md (session.json,
// trajectories.csv, events.jsonl), for sim_report and other readers. Bad content is a SessionLogError
// naming the file, the line and what is wrong; a torn last line (a write cut short by a kill) is dropped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "world/camera_mode.hpp"

namespace rfbsim::sim {

/// A session folder's content is not what docs/data.md describes. The message names the file, the line
/// (for trajectories.csv and events.jsonl) or key, and what is wrong:
/// "DIR/events.jsonl:12: key 'keysym': expected an integer".
class SessionLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The kinds of agent in trajectories.csv and session.json's agents.
enum class AgentKind { Avatar, Robot, Person };

/// "avatar", "robot" or "person", as written in the files.
const char* agent_kind_name(AgentKind kind);

/// One entry of session.json's `agents`.
struct SessionAgent {
  AgentKind kind = AgentKind::Avatar;
  int id = 0;           ///< 0 for the avatar and the robot; the person's id
  double radius = 0.0;  ///< body radius, m
};

/// One task step as the participant saw it.
struct SessionTask {
  std::string type;  ///< e.g. find_robot
  std::string text;
};

/// A moment of the session: a finished step or the outcome.
struct SessionMoment {
  std::uint64_t tick = 0;
  double time = 0.0;  ///< simulated s
};

/// A finished task step (session.json's `tasks_done`).
struct TaskDone : SessionMoment {
  std::string type;
};

/// The outcome's completion code and when it was shown (session.json's `completion`).
struct SessionCompletion : SessionMoment {
  std::string code;
};

/// Everything session.json holds (docs/data.md names each key). Optional members are null in the file.
struct SessionMeta {
  std::string uid;            ///< participant id from the link; may be empty, may hold any text
  std::string scenario;       ///< the scenario's name
  std::string scenario_file;  ///< the file it was loaded from; empty for the built-in test room
  std::map<std::string, std::string> parameters;  ///< the link's overrides as given
  std::uint64_t seed = 0;     ///< the master seed (a decimal string in the file)
  int tick_hz = 60;           ///< simulation ticks per second
  int fps = 30;               ///< rendered frames per second
  int trajectory_hz = 10;     ///< trajectory samples per second
  int frame_width = 0;        ///< px
  int frame_height = 0;       ///< px
  std::string rfbsim_version, build, scenario_sha256, map_sha256;  ///< session.json's `versions`
  std::vector<SessionAgent> agents;  ///< every agent in trajectories.csv
  std::vector<SessionTask> tasks;
  std::optional<double> time_limit_s;  ///< s; none without tasks
  std::optional<double> end_grace_s;   ///< s from the outcome to the end; none without tasks or in older files
  std::optional<std::string> success_code, timeout_code;  ///< the link's completion codes, if any
  CameraMode camera = CameraMode::kThirdPerson;  ///< the participant's view; third_person in older files
  std::string started_at;                ///< ISO 8601 UTC
  std::optional<std::string> ended_at;   ///< none while running or after a crash
  std::optional<std::uint64_t> end_tick;  ///< the last tick simulated, after a clean end
  std::optional<std::string> end_reason;  ///< completed, timeout, signal, error; none before the end
  std::optional<std::string> outcome;     ///< completed or timeout; none without an outcome
  std::optional<SessionCompletion> completion;
  std::vector<TaskDone> tasks_done;
  /// Why the recording stopped early (a full disk, a write error), when session.json says it did; the
  /// files then end at the failure, not at the session's end.
  std::optional<std::string> data_incomplete;
  std::uint64_t dropped_bytes = 0;  ///< bytes of lines the writer dropped after the failure
};

/// One row of trajectories.csv: an agent's pose and velocity at a sample tick.
struct TrajectoryRow {
  std::uint64_t tick = 0;
  double time = 0.0;  ///< simulated s
  AgentKind kind = AgentKind::Avatar;
  int id = 0;
  double x = 0.0, y = 0.0;    ///< body centre, m in the map frame
  double yaw = 0.0;           ///< rad
  double vx = 0.0, vy = 0.0;  ///< m/s in the map frame
};

/// One line of events.jsonl. The keys docs/data.md gives each known type are checked when read (a
/// `key` event has an integer keysym, a boolean down, an integer client; and so on), so the accessors
/// below find them; unknown types are kept as they are.
struct Event {
  std::uint64_t tick = 0;
  double time = 0.0;  ///< simulated s
  std::string type;   ///< session, key, pointer, client, contact, robot, task, timer, outcome, ...
  nlohmann::json fields = nlohmann::json::object();  ///< the line's other keys

  /// The string under `key`, or "" when there is none (never throws).
  [[nodiscard]] const std::string& text(const char* key) const;
  /// The integer under `key`, or `fallback` when there is none (never throws).
  [[nodiscard]] std::int64_t integer(const char* key, std::int64_t fallback = 0) const;
  /// The boolean under `key`, or false when there is none (never throws).
  [[nodiscard]] bool flag(const char* key) const;
};

/// A whole session folder.
struct SessionLog {
  std::filesystem::path dir;
  SessionMeta meta;
  std::vector<TrajectoryRow> trajectory;  ///< in file order
  std::vector<Event> events;              ///< in file order
  std::size_t torn_lines = 0;  ///< last lines without a newline dropped (0..2: one per appended file)
};

/// Reads and checks `dir`'s session.json, trajectories.csv and events.jsonl. Throws SessionLogError (and
/// nothing else) when a file is missing, unreadable or not as docs/data.md describes.
SessionLog read_session(const std::filesystem::path& dir);

/// The complete lines of an appended session file (trajectories.csv, events.jsonl), without their newlines;
/// a last line without its newline (a write cut short by a kill) is dropped. Throws SessionLogError for a
/// missing, unreadable or oversized file.
std::vector<std::string> read_complete_lines(const std::filesystem::path& file);

/// Every folder under `data_dir` (recursively, without following links) that holds a session.json,
/// sorted. Folders that cannot be read are passed over; none when `data_dir` is not a folder.
std::vector<std::filesystem::path> find_session_dirs(const std::filesystem::path& data_dir);

}  // namespace rfbsim::sim
