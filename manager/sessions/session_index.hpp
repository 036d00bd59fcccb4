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

#include "sessions/session.hpp"
#include "cluster/uid_registry.hpp"

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
  /// times) to its row; session.copy_state only where the row has none yet (a copy starts as 'pending'; from
  /// then on the copy columns are set_copy_status's alone).
  void update(const Session& session);
  /// update(), or insert() where the index has no row of session.id yet (its first write had failed).
  void write(const Session& session);
  /// What the writer does with each version of a session: insert() (`is_new`) or write(), and for a watcher
  /// (yoked_to set) its source's `watchers` counted again in the same transaction.
  void record(const Session& session, bool is_new);
  /// This host's sessions the video condition chooses among (sessions/yoking.hpp): interactive ones that may be
  /// shown (spent, ran their course) and every video one, oldest first.
  std::vector<Session> yoking_rows(const std::string& host_id);
  /// Records a session's after-session copy: its state ("pending", "done", "failed"), tries so far and last
  /// failure. Throws std::runtime_error when there is no such session.
  void set_copy_status(std::int64_t id, const std::string& state, int attempts, const std::string& error);
  /// This host's sessions whose copy is 'pending', oldest first: after a restart, the copies to try again.
  std::vector<Session> pending_copies(const std::string& host_id);

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

  /// The uid registry's acceptor state for `uid` (nothing promised or accepted when it has no row).
  AcceptorState uid_acceptor(const std::string& uid);
  /// Records `state` as `uid`'s acceptor state, committed before it returns; throws std::runtime_error on
  /// index errors (a counter past 2^63-1 included). `now`: when, for the researcher reading the table.
  void set_uid_acceptor(const std::string& uid, const AcceptorState& state, WallTime now);
  /// The highest ballot counter this acceptor promised for any uid (0: none): a restarted proposer starts
  /// above it, instead of learning it from one refused ballot per uid.
  std::uint64_t max_uid_ballot_counter();
  /// Whether opening this index created the uid registry's table: a new index, or one whose records were
  /// lost (rebuilt, deleted, or the first registry's table dropped). Several hosts warn about it.
  [[nodiscard]] bool registry_table_created() const { return registry_created_; }

 private:
  std::vector<Session> query(const std::string& where, const std::vector<std::string>& binds);
  void exec(const char* sql);
  void add_missing_columns();
  void prepare_registry_table();
  sqlite3* db_ = nullptr;
  bool registry_created_ = false;
  std::string path_;
};

/// ISO 8601 UTC with milliseconds ("2026-11-24T10:15:30.250Z"), as the index stores times.
std::string iso_utc(WallTime time);
/// The inverse of iso_utc; nothing for text it did not write.
std::optional<WallTime> parse_iso_utc(const std::string& text);

}  // namespace rfbsim::manager
