// SPDX-License-Identifier: GPL-2.0-or-later
// SessionWriter: writes one session's data folder as it runs (docs/data.md): session.json, replaced
// atomically whenever it changes; trajectories.csv and events.jsonl, appended and handed to the kernel at
// least every flush interval, so that a killed process loses at most that much.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

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
  std::optional<std::pair<std::string, std::string>> codes;  ///< (success, timeout)
};

/// How the session ended, for session.json's end keys.
struct SessionEnd {
  std::uint64_t tick = 0;
  std::string reason;  ///< completed, timeout, signal, error
};

class SessionWriter {
 public:
  /// Creates `dir` if needed and writes session.json (with `world`'s agents) and the CSV header. Throws
  /// std::runtime_error naming the path when it cannot, or when `dir` already holds a session.
  SessionWriter(std::filesystem::path dir, SessionInfo info, const World& world,
                std::chrono::milliseconds flush_interval = std::chrono::milliseconds(500));
  ~SessionWriter();
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  /// Appends the trajectory rows of `world` when its tick is a sample tick (every tick_hz / trajectory_hz).
  void sample(const World& world);
  /// Appends one event line: `fields` plus tick, time and type first.
  void event(std::uint64_t tick, const char* type, const nlohmann::ordered_json& fields = nlohmann::ordered_json::object());
  /// The contacts and robot state changes of the world's last tick, as events.
  void world_events(const World& world);

  /// A finished task step, or the outcome: session.json is rewritten at once.
  void task_done(const std::string& type, std::uint64_t tick);
  void outcome(const std::string& outcome, const std::string& code, std::uint64_t tick);
  /// The clean end: session.json gets its end keys, and everything is written out.
  void finish(const SessionEnd& end);

  /// Hands buffered lines to the kernel when the flush interval has passed (or the buffer grew large).
  void flush_if_due();
  /// Hands buffered lines to the kernel now. False when a write failed (a full disk): the lines not
  /// written stay buffered for the next flush, and the trouble is logged (at most every 10 s). Never throws:
  /// the participant's session goes on.
  bool flush();

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] double time_of(std::uint64_t tick) const { return static_cast<double>(tick) / info_.tick_hz; }

 private:
  void write_session_json();
  void update_session_json();  // write_session_json, logging a failure instead of throwing
  void write_buffers();        // throws std::runtime_error when a write fails
  void report_trouble(const std::string& what);

  // A descriptor closed with its owner, so that a constructor that throws halfway leaks none.
  struct OwnedFd {
    int fd = -1;
    OwnedFd() = default;
    OwnedFd(const OwnedFd&) = delete;
    OwnedFd& operator=(const OwnedFd&) = delete;
    ~OwnedFd();
  };

  std::filesystem::path dir_;
  SessionInfo info_;
  nlohmann::ordered_json session_;  // session.json as it stands
  OwnedFd trajectory_fd_, events_fd_;
  std::string trajectory_buffer_, events_buffer_;
  std::uint64_t sample_every_ = 6;
  std::chrono::milliseconds flush_interval_;
  std::chrono::steady_clock::time_point last_flush_;
  std::optional<std::chrono::steady_clock::time_point> last_trouble_report_;
};

/// Wall-clock time as ISO 8601 UTC with milliseconds: "2026-11-24T10:15:02.250Z".
std::string iso_utc_now();

}  // namespace rfbsim::sim
