// SPDX-License-Identifier: GPL-2.0-or-later
// WatchedReplay: a recorded session played to a watcher (sim_rfb --replay, the study's video condition). The
// recording is opened and checked as sim_replay opens it (replay/recording.hpp, the same build and files:
// replay/provenance.hpp), and driven by the same SessionReplay, which applies the recorded walker's inputs at
// their ticks; the watcher's own keys and pointer never reach it. sim_rfb paces it in real time and shows it
// through the same painter and server as a live session.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "record/session_log.hpp"
#include "replay/session_replay.hpp"
#include "task/task_display.hpp"

namespace rfbsim::sim {

class WatchedReplay {
 public:
  /// Opens the recording in `dir`. Throws replay::RecordingError naming the folder or file and what is wrong
  /// (missing, not a session, a corrupt log, another build or changed scenario files, a world that no longer
  /// loads).
  explicit WatchedReplay(const std::filesystem::path& dir);
  ~WatchedReplay();
  WatchedReplay(const WatchedReplay&) = delete;
  WatchedReplay& operator=(const WatchedReplay&) = delete;

  /// The recording's session.json.
  [[nodiscard]] const SessionMeta& meta() const { return log_.meta; }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] const World& world() const { return replay_->world(); }
  /// The tick the recording ends at (replay::recorded_end_tick).
  [[nodiscard]] std::uint64_t end_tick() const { return replay_->end_tick(); }

  /// What the HUD shows the watcher now: the walker's HUD less its prompts (watched_task_text), and once the
  /// recording has ended the watcher's own completion code, if set_watcher_code gave one.
  [[nodiscard]] TaskText text() const;
  /// The watcher's completion code (the video condition's, sim_rfb --code-success); "" = none to show.
  void set_watcher_code(std::string code) { watcher_code_ = std::move(code); }

  /// Plays up to `ticks` more ticks of the recording; at its end tick, applies the last inputs and stops.
  /// Returns whether the recording has ended. Throws sim::SessionLogError for inputs out of tick order.
  bool advance(int ticks);
  [[nodiscard]] bool ended() const { return ended_; }

  /// /status.json's "replay" member, without braces around it:
  /// "replay":{"recording":"DIR","uid":"p-01","end_tick":1200,"ended":false}.
  [[nodiscard]] std::string status_member() const;

 private:
  std::filesystem::path dir_;
  SessionLog log_;  // before replay_, which reads it for its whole life
  std::unique_ptr<replay::SessionReplay> replay_;
  bool ended_ = false;
  std::string watcher_code_;
};

/// Throws replay::RecordingError when `data_dir` (the watcher's --data-dir) is the recording's folder or
/// inside it: a replay never writes into its recording.
void check_watch_data_dir(const std::filesystem::path& data_dir, const std::filesystem::path& recording);

/// `status` (a JSON object's text, as status_json writes it) with `member` added as its last member.
std::string with_status_member(std::string status, const std::string& member);

}  // namespace rfbsim::sim
