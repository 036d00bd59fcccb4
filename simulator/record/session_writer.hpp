// SPDX-License-Identifier: GPL-2.0-or-later
// SessionWriter: writes one session's data folder as it runs (docs/data.md): session.json, replaced
// atomically whenever it changes; trajectories.csv and events.jsonl, appended in whole lines and synced to
// the disk at least every flush interval and at every task event, so that a killed process (or a power cut)
// loses at most that much. The disk work happens on a thread of its own (record/sync_queue.hpp): the
// simulation thread only formats lines. A full disk or any write error stops the recording, never the
// session: failure() then says why, and session.json carries the reason when the disk still takes it.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "record/sync_queue.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// What session.json says from the start (docs/data.md names each key).
struct SessionInfo {
  std::string uid;
  std::string scenario;
  std::string scenario_file;
  std::vector<std::pair<std::string, std::string>> parameters;  ///< the link's overrides, in order
  std::uint64_t seed = 0;
  int tick_hz = 60;
  int fps = 30;
  int trajectory_hz = 10;
  int width = 1280, height = 720;
  std::string rfbsim_version, build, scenario_sha256, map_sha256;
  std::vector<std::pair<std::string, std::string>> tasks;  ///< (type, text) per step
  std::optional<double> time_limit;  ///< s; none without a task
  std::optional<double> end_grace;   ///< s from the outcome to the session's end; none without a task
  std::optional<std::pair<std::string, std::string>> codes;  ///< (success, timeout)
  std::string robot_control;  ///< who drives the robot: "builtin" or "external"; empty = no robot
  std::string camera = "third_person";  ///< the participant's view: "third_person" or "first_person"
  /// What the session gave ROS (docs/ros.md): the bag's file name, the bridge ("server ADDR:PORT" or
  /// "client URL") and the topics' namespace; empty = none.
  std::string ros_bag, ros_bridge, ros_namespace;
};

/// How the session ended, for session.json's end keys.
struct SessionEnd {
  std::uint64_t tick = 0;
  std::string reason;  ///< completed, timeout, signal, error
};

/// How a SessionWriter writes; the defaults are sim_rfb's.
struct SessionWriterOptions {
  /// Wall time between hand-overs (and syncs) while data flows; at most 2 s keeps a crash's loss under 2 s.
  std::chrono::milliseconds flush_interval{500};
  SyncQueueLimits limits;  ///< the writer thread's memory bound and the space reserved for a failure note
  WriteFaults faults;      ///< tests only: a disk that fills or stalls on purpose
};

class SessionWriter {
 public:
  /// Creates `dir` if needed and writes session.json (with `world`'s agents) and the CSV header, synced.
  /// Throws std::runtime_error naming the path when it cannot, or when `dir` already holds a session.
  SessionWriter(std::filesystem::path dir, SessionInfo info, const World& world, SessionWriterOptions options = {});
  /// As above with the default options but `flush_interval`.
  SessionWriter(std::filesystem::path dir, SessionInfo info, const World& world,
                std::chrono::milliseconds flush_interval);
  /// Writes out what is buffered and waits for the writer thread to finish.
  ~SessionWriter();
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  /// Appends the trajectory rows of `world` when its tick is a sample tick (every tick_hz / trajectory_hz).
  void sample(const World& world);
  /// Appends one event line: `fields` plus tick, time and type first.
  void event(std::uint64_t tick, const char* type, const nlohmann::ordered_json& fields = nlohmann::ordered_json::object());
  /// Called with every event line (without its newline) as it is formatted, on the caller's thread: sim_rfb
  /// publishes the study's events on ROS's /events topic from it.
  void set_event_listener(std::function<void(std::uint64_t tick, const std::string& line)> listener) {
    event_listener_ = std::move(listener);
  }
  /// The contacts and robot state changes of the world's last tick, as events.
  void world_events(const World& world);

  /// A finished task step: session.json is rewritten, after the lines so far, and synced.
  void task_done(const std::string& type, std::uint64_t tick);
  /// The outcome: as task_done.
  void outcome(const std::string& outcome, const std::string& code, std::uint64_t tick);
  /// The clean end: session.json gets its end keys, everything is written out and synced, and the writer
  /// thread stops (waiting for the disk). Later calls record nothing.
  void finish(const SessionEnd& end);

  /// Hands buffered lines to the writer thread, with a sync, when the flush interval has passed (or the
  /// buffers grew large). Never waits for the disk.
  void flush_if_due();
  /// Hands buffered lines over with a sync now, without waiting: a task event, for instance.
  void checkpoint();
  /// Hands buffered lines over and waits until they are on disk. False when the recording has failed.
  /// Never throws: the participant's session goes on.
  bool flush();

  /// Why the recording stopped (a full disk, a write error, a disk that fell behind), on one line; none
  /// while all is well. Lines after the failure are dropped, and counted in dropped_bytes().
  [[nodiscard]] std::optional<std::string> failure() const { return queue_->failure(); }
  /// Bytes of lines dropped since the failure.
  [[nodiscard]] std::uint64_t dropped_bytes() const { return queue_->dropped_bytes(); }

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] double time_of(std::uint64_t tick) const { return static_cast<double>(tick) / info_.tick_hz; }

 private:
  void hand_over();  // the buffers to the writer thread, followed by a sync

  std::filesystem::path dir_;
  SessionInfo info_;
  nlohmann::ordered_json session_;  // session.json as it stands
  std::string trajectory_buffer_, events_buffer_;
  std::uint64_t sample_every_ = 6;
  std::chrono::milliseconds flush_interval_;
  std::chrono::steady_clock::time_point last_flush_;
  std::function<void(std::uint64_t, const std::string&)> event_listener_;
  std::unique_ptr<SyncQueue> queue_;  // last: started once the folder is in place
};

/// Wall-clock time as ISO 8601 UTC with milliseconds: "2026-11-24T10:15:02.250Z".
std::string iso_utc_now();

}  // namespace rfbsim::sim
