// SPDX-License-Identifier: GPL-2.0-or-later
// The session index: every session ever started on this data directory, in SQLite.
//
// Each change is one transaction, committed before the manager acts on it (a participant is redirected
// only once their session's row exists), in WAL mode with synchronous=FULL: a crash of the manager, or of
// the machine, loses nothing that was committed. One connection, used from one thread.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "session.hpp"

struct sqlite3;

namespace rfbsim::manager {

class SessionIndex {
 public:
  /// Opens (creating if needed) the index at `path`. `busy_timeout_ms`: how long a statement waits for a lock
  /// another connection holds (a researcher's sqlite3 shell, a checkpoint) before failing. Throws
  /// std::runtime_error naming the file and cause.
  explicit SessionIndex(const std::string& path, int busy_timeout_ms = 5000);
  ~SessionIndex();
  SessionIndex(const SessionIndex&) = delete;
  SessionIndex& operator=(const SessionIndex&) = delete;

  /// Inserts a new session and returns its id: session.id when it is above 0 (the caller chose it, see
  /// max_id()), else a new one.
  std::int64_t insert(const Session& session);
  /// The highest session id in the index (0 when empty): a manager hands out ids above it.
  std::int64_t max_id();
  /// The file this index lives in.
  [[nodiscard]] const std::string& path() const { return path_; }
  /// Writes a session's mutable fields (state, detail, exit status, pid, process start, port, data path,
  /// times) to its row.
  void update(const Session& session);

  /// The latest session of a uid, if any.
  std::optional<Session> latest_for_uid(const std::string& uid);
  /// The session with this token, if any.
  std::optional<Session> find_by_token(const std::string& token);
  /// Sessions of this host the index says are live (starting, running, ending): after a restart, the ones
  /// the previous manager left behind.
  std::vector<Session> live_sessions(const std::string& host_id);
  /// The newest `limit` sessions, newest first.
  std::vector<Session> recent(int limit);
  /// Sessions per state over the whole index.
  std::vector<std::pair<SessionState, std::int64_t>> count_by_state();

 private:
  std::vector<Session> query(const std::string& where, const std::vector<std::string>& binds);
  void exec(const char* sql);
  void add_missing_columns();
  sqlite3* db_ = nullptr;
  std::string path_;
};

/// ISO 8601 UTC with milliseconds ("2026-11-24T10:15:30.250Z"), as the index stores times.
std::string iso_utc(WallTime time);
/// The inverse of iso_utc; nothing for text it did not write.
std::optional<WallTime> parse_iso_utc(const std::string& text);

}  // namespace rfbsim::manager
