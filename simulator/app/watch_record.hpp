// SPDX-License-Identifier: GPL-2.0-or-later
// WatchRecord: what sim_rfb --replay records for the watcher's own session under --data-dir: one file,
// session.json with "condition": "video" (docs/data.md), naming the recording that was shown and how the
// watching ended. It is written when the replay starts and replaced atomically when it ends. The watcher walked
// nowhere and pressed nothing that counts, so there is no trajectories.csv or events.jsonl: sim_report lists the
// folder as a watcher of its source, sim_replay refuses it. The source's walker is named only by a keyed hash
// of their uid, never the uid or its folder (whose name holds the uid).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "record/session_log.hpp"

namespace rfbsim::sim {

class WatchRecord {
 public:
  /// Creates `data_dir` if needed and writes its session.json for the watcher `uid` of the recording whose
  /// session.json is `meta`: `yoked_to` is its id in sim_manager's index (none when run by hand),
  /// `uid_key` the key its walker's uid is hashed with (record/digest.hpp). Throws std::runtime_error naming
  /// the file when it cannot.
  WatchRecord(const std::filesystem::path& data_dir, const std::string& uid, const SessionMeta& meta,
              std::optional<std::int64_t> yoked_to, const std::string& uid_key);

  /// A viewer connected (counted; nothing of what it sends is kept).
  void viewer_connected() { ++viewers_; }

  /// Records the end: `reason` (watched, signal or error), the recording's tick reached, and the outcome
  /// "watched" when the recording was shown to its end. Returns "" or why session.json could not be replaced.
  std::string finish(const std::string& reason, std::uint64_t tick, bool watched);

 private:
  std::string write();

  std::filesystem::path dir_;
  nlohmann::json doc_;
  int viewers_ = 0;
};

}  // namespace rfbsim::sim
