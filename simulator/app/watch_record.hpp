// SPDX-License-Identifier: GPL-2.0-or-later
// WatchRecord: what sim_rfb --replay records for the watcher's own session under --data-dir: one file,
// watch.json (docs/data.md), naming the recording that was shown and how the watching ended. It is written
// when the replay starts and replaced atomically when it ends. Deliberately not a session.json: the watcher
// walked nowhere and pressed nothing that counts, so sim_report and sim_replay must not read the folder as a
// session of its own.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "record/session_log.hpp"

namespace rfbsim::sim {

class WatchRecord {
 public:
  /// Creates `data_dir` if needed and writes its watch.json for the watcher `uid` of the recording in
  /// `recording` (whose session.json is `meta`). Throws std::runtime_error naming the file when it cannot.
  WatchRecord(const std::filesystem::path& data_dir, const std::string& uid, const std::filesystem::path& recording,
              const SessionMeta& meta);

  /// A viewer connected (counted; nothing of what it sends is kept).
  void viewer_connected() { ++viewers_; }

  /// Records the end: `reason` (watched, signal or error), the recording's tick reached, and the outcome
  /// "watched" when the recording was shown to its end. Returns "" or why watch.json could not be replaced.
  std::string finish(const std::string& reason, std::uint64_t tick, bool watched);

 private:
  std::string write();

  std::filesystem::path dir_;
  nlohmann::json doc_;
  int viewers_ = 0;
};

}  // namespace rfbsim::sim
