// SPDX-License-Identifier: GPL-2.0-or-later
// The session index in SQLite.
#include "sessions/session_index.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <stdexcept>

namespace rfbsim::manager {

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS sessions (
  id            INTEGER PRIMARY KEY AUTOINCREMENT,
  uid           TEXT NOT NULL,
  token         TEXT NOT NULL UNIQUE,
  scenario      TEXT NOT NULL,
  params        TEXT NOT NULL,          -- the link's parameters, a JSON object
  seed          TEXT NOT NULL,          -- decimal: seeds are unsigned 64-bit
  host_id       TEXT NOT NULL,
  state         TEXT NOT NULL,          -- starting running ending finished expired idle ended shutdown
                                        -- crashed failed interrupted abandoned
  detail        TEXT NOT NULL DEFAULT '',
  exit_status   TEXT NOT NULL DEFAULT '',  -- "exit N" or "signal N" once the process is gone
  outcome       TEXT,                   -- the task's outcome as sim_rfb reported it: completed, timeout
  code_success  TEXT NOT NULL DEFAULT '',  -- the link's completion codes (t1, t2)
  code_timeout  TEXT NOT NULL DEFAULT '',
  pid           INTEGER,                -- also the process group id
  process_start INTEGER,                -- /proc start time in clock ticks: recognises the process later
  port          INTEGER,
  data_path     TEXT NOT NULL DEFAULT '',
  created_at    TEXT NOT NULL,          -- ISO 8601 UTC
  ready_at      TEXT,
  ended_at      TEXT,
  spent_at      TEXT,                   -- the first picture reached a participant: the link is spent
  data_incomplete TEXT,                 -- why the session's data is incomplete (a full disk...); NULL: complete
  copy_state    TEXT NOT NULL DEFAULT '',  -- after_session_command: '' none, pending, done, failed
  copy_attempts INTEGER NOT NULL DEFAULT 0,  -- tries of that command so far
  copy_error    TEXT NOT NULL DEFAULT '',  -- its last failure ("exit 23: ..."); '' when done
  address_hash  TEXT NOT NULL DEFAULT '',  -- keyed hash of the participant's address (as in events.jsonl)
  ros_namespace TEXT NOT NULL DEFAULT '',  -- its topics under the lab's ROS ("/rfbsim/s_12"); '' = no ROS
  robot_control TEXT NOT NULL DEFAULT '',  -- who drove the robot: builtin, external; '' = no robot known
  condition     TEXT NOT NULL DEFAULT 'interactive',  -- interactive, or video (a watcher of a replay)
  yoked_to      INTEGER,                -- video: the id of the session shown (on this host); NULL otherwise
  yoked_to_uid_hash TEXT NOT NULL DEFAULT '',  -- video: keyed hash of that session's uid (never the uid)
  watchers      INTEGER NOT NULL DEFAULT 0     -- interactive: the video sessions shown it that hold their place
);
CREATE INDEX IF NOT EXISTS sessions_by_uid ON sessions (uid, id);
CREATE INDEX IF NOT EXISTS sessions_by_state ON sessions (state);
)sql";

// The uid registry's acceptor (several hosts, manager/cluster/uid_registry.hpp): what this host promised and accepted
// for each uid it was asked about. A row is written, and committed, before the answer that depends on it.
constexpr const char* kRegistrySchema = R"sql(
CREATE TABLE IF NOT EXISTS uid_acceptors (
  uid               TEXT PRIMARY KEY,
  promised_counter  INTEGER NOT NULL DEFAULT 0,   -- the highest ballot promised: counter, proposer
  promised_proposer TEXT NOT NULL DEFAULT '',
  accepted_counter  INTEGER NOT NULL DEFAULT 0,   -- the ballot of the value accepted (0: none)
  accepted_proposer TEXT NOT NULL DEFAULT '',
  accepted_value    TEXT NOT NULL DEFAULT '',     -- a host id, '' when none
  updated_at        TEXT                          -- ISO 8601 UTC
);
)sql";

constexpr const char* kColumns =
    "id, uid, token, scenario, params, seed, host_id, state, detail, exit_status, pid, process_start, port, "
    "data_path, created_at, ready_at, ended_at, outcome, code_success, code_timeout, spent_at, data_incomplete, "
    "copy_state, copy_attempts, copy_error, address_hash, ros_namespace, robot_control, condition, yoked_to, "
    "yoked_to_uid_hash, watchers";

// The states in which a watcher holds its place with its source (sessions/yoking.hpp): live, or ran its
// course. A watcher that failed, crashed, was interrupted or shut down, or never showed a picture, frees it.
constexpr const char* kHoldingStates = "('starting', 'running', 'ending', 'finished', 'expired', 'idle', 'ended')";

// One prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("session index: ") + sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind(int index, const std::string& text) {
    sqlite3_bind_text(stmt_, index, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
  }
  void bind(int index, std::int64_t value) { sqlite3_bind_int64(stmt_, index, value); }
  void bind_null(int index) { sqlite3_bind_null(stmt_, index); }
  void bind(int index, const std::optional<WallTime>& time) {
    if (time) {
      bind(index, iso_utc(*time));
    } else {
      sqlite3_bind_null(stmt_, index);
    }
  }
  // Returns true while there is a row; throws on errors.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw std::runtime_error(std::string("session index: ") + sqlite3_errmsg(db_));
  }
  std::string text(int column) {
    const auto* value = sqlite3_column_text(stmt_, column);
    return value == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(value));
  }
  std::int64_t integer(int column) { return sqlite3_column_int64(stmt_, column); }
  bool is_null(int column) { return sqlite3_column_type(stmt_, column) == SQLITE_NULL; }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

Session read_row(Statement& row) {
  Session s;
  s.id = row.integer(0);
  s.uid = row.text(1);
  s.token = row.text(2);
  s.scenario = row.text(3);
  s.params_json = row.text(4);
  s.seed = std::strtoull(row.text(5).c_str(), nullptr, 10);
  s.host_id = row.text(6);
  s.state = state_from_name(row.text(7)).value_or(SessionState::kInterrupted);
  s.detail = row.text(8);
  s.exit_status = row.text(9);
  s.pid = static_cast<pid_t>(row.integer(10));
  s.process_start = row.integer(11);
  s.port = static_cast<int>(row.integer(12));
  s.data_path = row.text(13);
  s.created = parse_iso_utc(row.text(14)).value_or(WallTime{});
  if (!row.is_null(15)) s.ready_at = parse_iso_utc(row.text(15));
  if (!row.is_null(16)) s.ended_at = parse_iso_utc(row.text(16));
  s.outcome = row.text(17);
  s.code_success = row.text(18);
  s.code_timeout = row.text(19);
  if (!row.is_null(20)) s.spent_at = parse_iso_utc(row.text(20));
  s.data_incomplete = row.text(21);
  s.copy_state = row.text(22);
  s.copy_attempts = static_cast<int>(row.integer(23));
  s.copy_error = row.text(24);
  s.address_hash = row.text(25);
  s.ros_namespace = row.text(26);
  s.robot_control = row.text(27);
  s.condition = row.text(28);
  s.yoked_to = row.is_null(29) ? 0 : row.integer(29);
  s.yoked_to_uid_hash = row.text(30);
  s.watchers = static_cast<int>(row.integer(31));
  return s;
}

}  // namespace

std::string iso_utc(WallTime time) {
  const auto since_epoch = std::chrono::duration_cast<std::chrono::milliseconds>(time.time_since_epoch());
  const std::time_t seconds = static_cast<std::time_t>(since_epoch.count() / 1000);
  const int millis = static_cast<int>(since_epoch.count() % 1000);
  std::tm parts{};
  gmtime_r(&seconds, &parts);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", parts.tm_year + 1900, parts.tm_mon + 1,
                parts.tm_mday, parts.tm_hour, parts.tm_min, parts.tm_sec, millis);
  return text;
}

std::optional<WallTime> parse_iso_utc(const std::string& text) {
  std::tm parts{};
  int millis = 0;
  char zone = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d.%3d%c", &parts.tm_year, &parts.tm_mon, &parts.tm_mday,
                  &parts.tm_hour, &parts.tm_min, &parts.tm_sec, &millis, &zone) != 8 ||
      zone != 'Z') {
    return std::nullopt;
  }
  parts.tm_year -= 1900;
  parts.tm_mon -= 1;
  const std::time_t seconds = timegm(&parts);
  const WallTime time(std::chrono::duration_cast<WallTime::duration>(std::chrono::seconds(seconds) +
                                                                     std::chrono::milliseconds(millis)));
  // sscanf takes trailing text, short or signed fields and out-of-range dates (which timegm normalizes):
  // only text that iso_utc writes back the same is ours.
  if (iso_utc(time) != text) return std::nullopt;
  return time;
}

SessionIndex::SessionIndex(const std::string& path, int busy_timeout_ms) : path_(path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error("session index " + path + ": " + message);
  }
  try {
    // Another connection (a researcher's sqlite3 shell) may hold a lock for a moment: wait rather than fail.
    sqlite3_busy_timeout(db_, busy_timeout_ms);
    exec("PRAGMA journal_mode = WAL");
    exec("PRAGMA synchronous = FULL");
    exec(kSchema);
    add_missing_columns();
    prepare_registry_table();
  } catch (const std::exception& error) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error("session index " + path + ": " + error.what());
  }
}

SessionIndex::~SessionIndex() { sqlite3_close(db_); }

void SessionIndex::add_missing_columns() {
  // An index made by an earlier version lacks the later columns: add them, so that a study can keep its
  // index across an upgrade.
  bool has_codes = false;
  bool has_spent = false;
  bool has_copy = false;
  bool has_address_hash = false;
  bool has_ros_namespace = false;
  bool has_robot_control = false;
  bool has_condition = false;
  {
    Statement columns(db_, "PRAGMA table_info(sessions)");
    while (columns.step()) {
      has_codes = has_codes || columns.text(1) == "code_success";
      has_spent = has_spent || columns.text(1) == "spent_at";
      has_copy = has_copy || columns.text(1) == "copy_state";
      has_address_hash = has_address_hash || columns.text(1) == "address_hash";
      has_ros_namespace = has_ros_namespace || columns.text(1) == "ros_namespace";
      has_robot_control = has_robot_control || columns.text(1) == "robot_control";
      has_condition = has_condition || columns.text(1) == "condition";
    }
  }
  if (!has_codes) {
    exec("ALTER TABLE sessions ADD COLUMN code_success TEXT NOT NULL DEFAULT ''");
    exec("ALTER TABLE sessions ADD COLUMN code_timeout TEXT NOT NULL DEFAULT ''");
  }
  if (!has_spent) {
    exec("ALTER TABLE sessions ADD COLUMN spent_at TEXT");
    exec("ALTER TABLE sessions ADD COLUMN data_incomplete TEXT");
  }
  if (!has_copy) {
    exec("ALTER TABLE sessions ADD COLUMN copy_state TEXT NOT NULL DEFAULT ''");
    exec("ALTER TABLE sessions ADD COLUMN copy_attempts INTEGER NOT NULL DEFAULT 0");
    exec("ALTER TABLE sessions ADD COLUMN copy_error TEXT NOT NULL DEFAULT ''");
  }
  // Sessions recorded before it keep '': their participants' addresses were never hashed.
  if (!has_address_hash) exec("ALTER TABLE sessions ADD COLUMN address_hash TEXT NOT NULL DEFAULT ''");
  // Sessions recorded before ROS keep '': none of them had any. Each column on its own, so that a crash
  // between the two leaves nothing half-done for the next start.
  if (!has_ros_namespace) exec("ALTER TABLE sessions ADD COLUMN ros_namespace TEXT NOT NULL DEFAULT ''");
  if (!has_robot_control) exec("ALTER TABLE sessions ADD COLUMN robot_control TEXT NOT NULL DEFAULT ''");
  // Sessions recorded before the video condition were all interactive. One transaction: all four or none.
  if (!has_condition) {
    exec("BEGIN IMMEDIATE");
    try {
      exec("ALTER TABLE sessions ADD COLUMN condition TEXT NOT NULL DEFAULT 'interactive'");
      exec("ALTER TABLE sessions ADD COLUMN yoked_to INTEGER");
      exec("ALTER TABLE sessions ADD COLUMN yoked_to_uid_hash TEXT NOT NULL DEFAULT ''");
      exec("ALTER TABLE sessions ADD COLUMN watchers INTEGER NOT NULL DEFAULT 0");
      exec("COMMIT");
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
  }
  exec("CREATE INDEX IF NOT EXISTS sessions_by_source ON sessions (yoked_to)");
}

void SessionIndex::exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message != nullptr ? message : "unknown error";
    sqlite3_free(message);
    throw std::runtime_error(text);
  }
}

std::int64_t SessionIndex::insert(const Session& s) {
  Statement insert(db_,
                   "INSERT INTO sessions (uid, token, scenario, params, seed, host_id, state, detail, pid, "
                   "process_start, port, data_path, created_at, code_success, code_timeout, spent_at, address_hash, "
                   "ros_namespace, robot_control, condition, yoked_to, yoked_to_uid_hash, id) "
                   "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  insert.bind(1, s.uid);
  insert.bind(2, s.token);
  insert.bind(3, s.scenario);
  insert.bind(4, s.params_json);
  insert.bind(5, std::to_string(s.seed));
  insert.bind(6, s.host_id);
  insert.bind(7, std::string(state_name(s.state)));
  insert.bind(8, s.detail);
  insert.bind(9, static_cast<std::int64_t>(s.pid));
  insert.bind(10, s.process_start);
  insert.bind(11, static_cast<std::int64_t>(s.port));
  insert.bind(12, s.data_path);
  insert.bind(13, iso_utc(s.created));
  insert.bind(14, s.code_success);
  insert.bind(15, s.code_timeout);
  insert.bind(16, s.spent_at);
  insert.bind(17, s.address_hash);
  insert.bind(18, s.ros_namespace);
  insert.bind(19, s.robot_control);
  insert.bind(20, s.condition);
  if (s.yoked_to > 0) {
    insert.bind(21, s.yoked_to);
  } else {
    insert.bind_null(21);
  }
  insert.bind(22, s.yoked_to_uid_hash);
  if (s.id > 0) {
    insert.bind(23, s.id);
  } else {
    insert.bind_null(23);  // SQLite picks the next id
  }
  insert.step();
  return sqlite3_last_insert_rowid(db_);
}

std::int64_t SessionIndex::max_id() {
  // AUTOINCREMENT's own record too: an id of a deleted row is never handed out again.
  Statement select(db_,
                   "SELECT MAX(COALESCE((SELECT MAX(id) FROM sessions), 0), "
                   "COALESCE((SELECT seq FROM sqlite_sequence WHERE name = 'sessions'), 0))");
  return select.step() ? select.integer(0) : 0;
}

void SessionIndex::update(const Session& s) {
  Statement update(db_,
                   "UPDATE sessions SET state = ?, detail = ?, exit_status = ?, pid = ?, process_start = ?, "
                   "port = ?, data_path = ?, ready_at = ?, ended_at = ?, outcome = ?, spent_at = ?, "
                   "data_incomplete = ?, copy_state = CASE WHEN copy_state = '' THEN ? ELSE copy_state END "
                   "WHERE id = ?");
  update.bind(1, std::string(state_name(s.state)));
  update.bind(2, s.detail);
  update.bind(3, s.exit_status);
  update.bind(4, static_cast<std::int64_t>(s.pid));
  update.bind(5, s.process_start);
  update.bind(6, static_cast<std::int64_t>(s.port));
  update.bind(7, s.data_path);
  update.bind(8, s.ready_at);
  update.bind(9, s.ended_at);
  if (s.outcome.empty()) {
    update.bind_null(10);
  } else {
    update.bind(10, s.outcome);
  }
  update.bind(11, s.spent_at);
  if (s.data_incomplete.empty()) {
    update.bind_null(12);
  } else {
    update.bind(12, s.data_incomplete);
  }
  // The copy columns belong to the copier (set_copy_status); an update only starts a copy, as 'pending' in the
  // same transaction as the session's end, so that a crash in between cannot lose it.
  update.bind(13, s.copy_state);
  update.bind(14, s.id);
  update.step();
  if (sqlite3_changes(db_) != 1) {
    throw std::runtime_error("session index: no session " + std::to_string(s.id) + " to update");
  }
}

void SessionIndex::write(const Session& s) {
  bool present = false;
  {
    // Finished before the write: a read still open would make the write an upgrade of its snapshot, which
    // SQLite refuses at once (no busy wait) whenever another connection wrote meanwhile.
    Statement select(db_, "SELECT 1 FROM sessions WHERE id = ?");
    select.bind(1, s.id);
    present = select.step();
  }
  if (present) {
    update(s);
  } else {
    insert(s);
  }
}

void SessionIndex::record(const Session& s, bool is_new) {
  if (s.yoked_to <= 0) {
    is_new ? static_cast<void>(insert(s)) : write(s);
    return;
  }
  // A watcher's row and its source's count change together: a crash between them cannot leave a count that
  // disagrees with the rows (the count is what the researcher reads; the choice counts the rows themselves).
  exec("BEGIN IMMEDIATE");
  try {
    is_new ? static_cast<void>(insert(s)) : write(s);
    Statement count(db_, std::string("UPDATE sessions SET watchers = (SELECT COUNT(*) FROM sessions WHERE yoked_to = ?1 "
                                     "AND state IN ") + kHoldingStates + ") WHERE id = ?1");
    count.bind(1, s.yoked_to);
    count.step();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::vector<Session> SessionIndex::yoking_rows(const std::string& host_id) {
  // Sources that may be shown (interactive, spent, ran their course) and every watcher: the choice needs the
  // watchers of all scenarios to know who is paired with whom (yoke_policy by_participant).
  return query("WHERE host_id = ? AND ((condition = 'interactive' AND spent_at IS NOT NULL AND state IN "
               "('finished', 'expired', 'idle', 'ended')) OR condition = 'video') ORDER BY id",
               {host_id});
}

std::vector<Session> SessionIndex::query(const std::string& where, const std::vector<std::string>& binds) {
  Statement select(db_, std::string("SELECT ") + kColumns + " FROM sessions " + where);
  for (std::size_t i = 0; i < binds.size(); ++i) select.bind(static_cast<int>(i + 1), binds[i]);
  std::vector<Session> rows;
  while (select.step()) rows.push_back(read_row(select));
  return rows;
}

std::optional<Session> SessionIndex::latest_for_uid(const std::string& uid) {
  auto rows = query("WHERE uid = ? ORDER BY id DESC LIMIT 1", {uid});
  if (rows.empty()) return std::nullopt;
  return std::move(rows.front());
}

std::optional<Session> SessionIndex::find_by_token(const std::string& token) {
  auto rows = query("WHERE token = ?", {token});
  if (rows.empty()) return std::nullopt;
  return std::move(rows.front());
}

std::vector<Session> SessionIndex::live_sessions(const std::string& host_id) {
  return query("WHERE host_id = ? AND state IN ('starting', 'running', 'ending') ORDER BY id", {host_id});
}

void SessionIndex::set_copy_status(std::int64_t id, const std::string& state, int attempts, const std::string& error) {
  Statement update(db_, "UPDATE sessions SET copy_state = ?, copy_attempts = ?, copy_error = ? WHERE id = ?");
  update.bind(1, state);
  update.bind(2, static_cast<std::int64_t>(attempts));
  update.bind(3, error);
  update.bind(4, id);
  update.step();
  if (sqlite3_changes(db_) != 1) {
    throw std::runtime_error("session index: no session " + std::to_string(id) + " to record a copy for");
  }
}

std::vector<Session> SessionIndex::pending_copies(const std::string& host_id) {
  return query("WHERE host_id = ? AND copy_state = 'pending' ORDER BY id", {host_id});
}

std::vector<Session> SessionIndex::recent(int limit) {
  return query("ORDER BY id DESC LIMIT " + std::to_string(limit), {});
}

void SessionIndex::prepare_registry_table() {
  bool had_acceptors = false;
  bool had_first_wins = false;
  {
    Statement tables(db_,
                     "SELECT name FROM sqlite_master WHERE type = 'table' AND name IN ('uid_acceptors', 'uid_homes')");
    while (tables.step()) {
      had_acceptors = had_acceptors || tables.text(0) == "uid_acceptors";
      had_first_wins = had_first_wins || tables.text(0) == "uid_homes";
    }
  }
  // The first registry kept one first-answered home per uid (uid_homes); its records are no Paxos state, and
  // nothing shipped with it: dropped, and the start-up warning about a new registry table says so.
  if (had_first_wins) exec("DROP TABLE uid_homes");
  exec(kRegistrySchema);
  registry_created_ = !had_acceptors;
}

AcceptorState SessionIndex::uid_acceptor(const std::string& uid) {
  Statement select(db_,
                   "SELECT promised_counter, promised_proposer, accepted_counter, accepted_proposer, accepted_value "
                   "FROM uid_acceptors WHERE uid = ?");
  select.bind(1, uid);
  AcceptorState state;
  if (!select.step()) return state;
  state.promised = Ballot{static_cast<std::uint64_t>(select.integer(0)), select.text(1)};
  state.accepted = Ballot{static_cast<std::uint64_t>(select.integer(2)), select.text(3)};
  state.value = select.text(4);
  return state;
}

std::uint64_t SessionIndex::max_uid_ballot_counter() {
  Statement select(db_, "SELECT MAX(promised_counter) FROM uid_acceptors");
  if (!select.step() || select.is_null(0)) return 0;
  return static_cast<std::uint64_t>(std::max<std::int64_t>(0, select.integer(0)));
}

void SessionIndex::set_uid_acceptor(const std::string& uid, const AcceptorState& state, WallTime now) {
  // SQLite's integers are signed 64-bit (parse_message refuses larger counters).
  if (state.promised.counter > kMaxBallotCounter ||
      state.accepted.counter > kMaxBallotCounter) {
    throw std::runtime_error("session index: ballot counter of uid " + uid + " out of range");
  }
  Statement upsert(db_,
                   "INSERT OR REPLACE INTO uid_acceptors (uid, promised_counter, promised_proposer, accepted_counter, "
                   "accepted_proposer, accepted_value, updated_at) VALUES (?,?,?,?,?,?,?)");
  upsert.bind(1, uid);
  upsert.bind(2, static_cast<std::int64_t>(state.promised.counter));
  upsert.bind(3, state.promised.proposer);
  upsert.bind(4, static_cast<std::int64_t>(state.accepted.counter));
  upsert.bind(5, state.accepted.proposer);
  upsert.bind(6, state.value);
  upsert.bind(7, iso_utc(now));
  upsert.step();
}

std::vector<std::pair<SessionState, std::int64_t>> SessionIndex::count_by_state() {
  Statement select(db_, "SELECT state, COUNT(*) FROM sessions GROUP BY state");
  std::vector<std::pair<SessionState, std::int64_t>> counts;
  while (select.step()) {
    if (const auto state = state_from_name(select.text(0))) counts.emplace_back(*state, select.integer(1));
  }
  return counts;
}

}  // namespace rfbsim::manager
