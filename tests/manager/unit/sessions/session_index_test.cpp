// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <sqlite3.h>

#include <map>
#include <stdexcept>

#include "scratch_dir.hpp"
#include "sessions/session_index.hpp"

using rfbsim::manager::iso_utc;
using rfbsim::manager::parse_iso_utc;
using rfbsim::manager::Session;
using rfbsim::manager::SessionIndex;
using rfbsim::manager::SessionState;
using rfbsim::manager::WallTime;
using rfbsim::test::ScratchDir;

namespace {

// 2026-11-24T10:15:30.250Z
const WallTime kCreated{std::chrono::milliseconds(1795515330250)};

WallTime at_ms(std::int64_t milliseconds) { return WallTime(std::chrono::milliseconds(milliseconds)); }

// A new session row; the token derives from the uid and a counter so that each is unique.
Session make(const std::string& uid, SessionState state = SessionState::kStarting, const std::string& host = "host-a") {
  static int counter = 0;
  const std::string number = std::to_string(++counter);
  Session s;
  s.uid = uid;
  s.token = std::string(32 - number.size(), 'b') + number;
  s.scenario = "lab";
  s.params_json = "{\"uid\":\"" + uid + "\"}";
  s.seed = 42;
  s.host_id = host;
  s.state = state;
  s.created = kCreated;
  return s;
}

std::vector<std::int64_t> ids(const std::vector<Session>& sessions) {
  std::vector<std::int64_t> out;
  for (const Session& s : sessions) out.push_back(s.id);
  return out;
}

// Runs one query on its own connection and returns the first column of the first row.
std::string sql_text(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(path.c_str(), &db) == SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  REQUIRE(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) == SQLITE_OK);
  std::string out;
  if (sqlite3_step(stmt) == SQLITE_ROW && sqlite3_column_text(stmt, 0) != nullptr) {
    out = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return out;
}

}  // namespace

TEST_CASE("iso_utc writes UTC with milliseconds") {
  CHECK(iso_utc(kCreated) == "2026-11-24T10:15:30.250Z");
  CHECK(iso_utc(WallTime{}) == "1970-01-01T00:00:00.000Z");
  CHECK(iso_utc(at_ms(951868799999)) == "2000-02-29T23:59:59.999Z");
  CHECK(iso_utc(at_ms(1795515600007)) == "2026-11-24T10:20:00.007Z");
  // Below a millisecond is cut, not rounded.
  CHECK(iso_utc(kCreated + std::chrono::microseconds(999)) == "2026-11-24T10:15:30.250Z");
}

TEST_CASE("parse_iso_utc reads back what iso_utc wrote") {
  for (const std::int64_t ms : {std::int64_t{0}, std::int64_t{951868799999}, std::int64_t{1795515330250},
                                std::int64_t{1795515600007}}) {
    INFO(ms);
    CHECK(parse_iso_utc(iso_utc(at_ms(ms))) == at_ms(ms));
  }
  CHECK(parse_iso_utc("2026-11-24T10:15:30.250Z") == kCreated);
}

TEST_CASE("parse_iso_utc refuses text that iso_utc does not write") {
  for (const char* text : {"", "yesterday", "2026-11-24", "2026-11-24T10:15:30Z", "2026-11-24T10:15:30.250",
                           "2026-11-24 10:15:30.250Z", "2026-11-24T10:15:30.250+01:00", "2026-11-24T10:15:30.250z",
                           "2026-11-24T10:15:30.250Zjunk", "2026-11-24T10:15:30.5Z", "2026-13-24T10:15:30.250Z",
                           "2026-11-31T10:15:30.250Z", "2026-11-24T24:15:30.250Z", "2026-11-24T10:15:30.-50Z",
                           " 2026-11-24T10:15:30.250Z"}) {
    INFO(text);
    CHECK_FALSE(parse_iso_utc(text));
  }
}

TEST_CASE("opening an index in a missing folder throws naming the file") {
  ScratchDir dir;
  const std::string path = dir.path("missing/sessions.db");
  CHECK_THROWS_AS(SessionIndex(path), std::runtime_error);
  CHECK_THROWS_WITH(SessionIndex(path), Catch::Contains("session index " + path + ": "));
}

TEST_CASE("the index is kept in WAL mode") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  { SessionIndex index(path); }
  CHECK(sql_text(path, "PRAGMA journal_mode") == "wal");
}

TEST_CASE("insert returns increasing ids and a new index is empty") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  CHECK(index.recent(10).empty());
  CHECK(index.count_by_state().empty());
  CHECK_FALSE(index.latest_for_uid("p01"));
  CHECK(index.insert(make("p01")) == 1);
  CHECK(index.insert(make("p02")) == 2);
  CHECK(index.max_id() == 2);
  // An id the caller chose (the manager hands them out itself, to write rows off its I/O thread).
  Session with_id = make("p03");
  with_id.id = 77;
  CHECK(index.insert(with_id) == 77);
  CHECK(index.max_id() == 77);
  CHECK(index.insert(make("p04")) == 78);
}

TEST_CASE("a token is unique in the index") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  Session first = make("p01");
  index.insert(first);
  Session second = make("p02");
  second.token = first.token;
  CHECK_THROWS_AS(index.insert(second), std::runtime_error);
}

TEST_CASE("an inserted session reads back as written") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  Session s = make("p01");
  s.seed = 18446744073709551615ULL;
  s.detail = "starting";
  s.pid = 4321;
  s.process_start = 987654;
  s.port = 5901;
  s.data_path = "/data/sessions/1";
  s.id = index.insert(s);
  const auto back = index.find_by_token(s.token);
  REQUIRE(back);
  CHECK(back->id == 1);
  CHECK(back->uid == "p01");
  CHECK(back->token == s.token);
  CHECK(back->scenario == "lab");
  CHECK(back->params_json == "{\"uid\":\"p01\"}");
  CHECK(back->seed == 18446744073709551615ULL);
  CHECK(back->host_id == "host-a");
  CHECK(back->state == SessionState::kStarting);
  CHECK(back->detail == "starting");
  CHECK(back->exit_status.empty());
  CHECK(back->pid == 4321);
  CHECK(back->process_start == 987654);
  CHECK(back->port == 5901);
  CHECK(back->data_path == "/data/sessions/1");
  CHECK(back->created == kCreated);
  CHECK_FALSE(back->ready_at);
  CHECK_FALSE(back->ended_at);
  CHECK_FALSE(index.find_by_token(std::string(32, 'f')));
}

TEST_CASE("update writes every mutable field") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  Session s = make("p01");
  s.id = index.insert(s);
  index.insert(make("p02"));  // an unrelated row that must not change

  s.state = SessionState::kCrashed;
  s.detail = "exit status 2: bad map";
  s.exit_status = "exit 2";
  s.pid = 777;
  s.process_start = 123456789012;
  s.port = 40000;
  s.data_path = "/srv/rfbsim/sessions/p01-1";
  s.ready_at = at_ms(1795515331000);
  s.ended_at = at_ms(1795515600007);
  index.update(s);

  const auto back = index.find_by_token(s.token);
  REQUIRE(back);
  CHECK(back->state == SessionState::kCrashed);
  CHECK(back->detail == "exit status 2: bad map");
  CHECK(back->exit_status == "exit 2");
  CHECK(back->pid == 777);
  CHECK(back->process_start == 123456789012);
  CHECK(back->port == 40000);
  CHECK(back->data_path == "/srv/rfbsim/sessions/p01-1");
  CHECK(back->ready_at == at_ms(1795515331000));
  CHECK(back->ended_at == at_ms(1795515600007));
  CHECK(back->created == kCreated);
  CHECK(back->uid == "p01");

  const auto other = index.latest_for_uid("p02");
  REQUIRE(other);
  CHECK(other->state == SessionState::kStarting);
  CHECK(other->exit_status.empty());
  CHECK_FALSE(other->ended_at);

  SECTION("times can be cleared again") {
    s.ready_at.reset();
    s.ended_at.reset();
    index.update(s);
    const auto cleared = index.find_by_token(s.token);
    REQUIRE(cleared);
    CHECK_FALSE(cleared->ready_at);
    CHECK_FALSE(cleared->ended_at);
  }
}

TEST_CASE("update of a session that is not in the index throws") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  Session s = make("p01");
  s.id = 5;
  CHECK_THROWS_WITH(index.update(s), "session index: no session 5 to update");
}

TEST_CASE("latest_for_uid returns the newest session of that uid") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  Session first = make("p01", SessionState::kCrashed);
  index.insert(first);
  index.insert(make("p02"));
  Session second = make("p01", SessionState::kRunning);
  index.insert(second);
  index.insert(make("p03"));
  const auto latest = index.latest_for_uid("p01");
  REQUIRE(latest);
  CHECK(latest->id == 3);
  CHECK(latest->token == second.token);
  CHECK(latest->state == SessionState::kRunning);
  CHECK_FALSE(index.latest_for_uid("p04"));
  CHECK_FALSE(index.latest_for_uid("P01"));
}

TEST_CASE("live_sessions lists this host's starting, running and ending sessions in id order") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  index.insert(make("a1", SessionState::kRunning));                 // 1
  index.insert(make("a2", SessionState::kFinished));                // 2
  index.insert(make("b1", SessionState::kRunning, "host-b"));       // 3
  index.insert(make("a3", SessionState::kStarting));                // 4
  index.insert(make("a4", SessionState::kCrashed));                 // 5
  index.insert(make("a5", SessionState::kEnding));                  // 6
  index.insert(make("a6", SessionState::kInterrupted));             // 7
  CHECK(ids(index.live_sessions("host-a")) == std::vector<std::int64_t>{1, 4, 6});
  CHECK(ids(index.live_sessions("host-b")) == std::vector<std::int64_t>{3});
  CHECK(index.live_sessions("host-c").empty());
  CHECK(index.live_sessions("host-a")[1].uid == "a3");
}

TEST_CASE("recent lists the newest sessions first, at most limit") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  for (int i = 1; i <= 5; ++i) index.insert(make("p" + std::to_string(i)));
  CHECK(ids(index.recent(3)) == std::vector<std::int64_t>{5, 4, 3});
  CHECK(ids(index.recent(10)) == std::vector<std::int64_t>{5, 4, 3, 2, 1});
  CHECK(index.recent(0).empty());
  CHECK(index.recent(1)[0].uid == "p5");
}

TEST_CASE("count_by_state counts every session by its state") {
  ScratchDir dir;
  SessionIndex index(dir.path("sessions.db"));
  for (const SessionState state : {SessionState::kRunning, SessionState::kFinished, SessionState::kFinished,
                                   SessionState::kCrashed, SessionState::kFinished}) {
    index.insert(make("p", state));
  }
  Session moved = make("q", SessionState::kRunning);
  moved.id = index.insert(moved);
  moved.state = SessionState::kExpired;
  index.update(moved);
  const auto counts = index.count_by_state();
  const std::map<SessionState, std::int64_t> by_state(counts.begin(), counts.end());
  CHECK(counts.size() == 4);
  CHECK(by_state == std::map<SessionState, std::int64_t>{{SessionState::kRunning, 1},
                                                         {SessionState::kFinished, 3},
                                                         {SessionState::kCrashed, 1},
                                                         {SessionState::kExpired, 1}});
}

TEST_CASE("what was committed is still there after closing and reopening the file") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  Session s = make("p01");
  {
    SessionIndex index(path);
    s.id = index.insert(s);
    s.state = SessionState::kRunning;
    s.port = 5901;
    s.ready_at = at_ms(1795515331000);
    index.update(s);
    index.insert(make("p02", SessionState::kFailed));
  }
  SessionIndex reopened(path);
  const auto back = reopened.find_by_token(s.token);
  REQUIRE(back);
  CHECK(back->id == 1);
  CHECK(back->state == SessionState::kRunning);
  CHECK(back->port == 5901);
  CHECK(back->ready_at == at_ms(1795515331000));
  CHECK(ids(reopened.live_sessions("host-a")) == std::vector<std::int64_t>{1});
  CHECK(ids(reopened.recent(5)) == std::vector<std::int64_t>{2, 1});
  // Ids go on from where they were.
  CHECK(reopened.insert(make("p03")) == 3);
}

TEST_CASE("a row with a state the manager does not know reads as interrupted") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  SessionIndex index(path);
  index.insert(make("p01", SessionState::kRunning));
  sql_text(path, "UPDATE sessions SET state = 'paused' WHERE id = 1");
  const auto back = index.latest_for_uid("p01");
  REQUIRE(back);
  CHECK(back->state == SessionState::kInterrupted);
}

TEST_CASE("the participant's address hash is written with the row and kept by updates") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  SessionIndex index(path);
  Session s = make("p01");
  s.address_hash = "0123456789abcdef";
  s.id = index.insert(s);
  s.state = SessionState::kRunning;
  s.address_hash = "ffffffffffffffff";  // not a mutable field: update leaves the row's alone
  index.update(s);
  CHECK(sql_text(path, "SELECT address_hash FROM sessions WHERE id = 1") == "0123456789abcdef");
  const auto back = index.find_by_token(s.token);
  REQUIRE(back);
  CHECK(back->address_hash == "0123456789abcdef");
  // A session whose participant's address is unknown has ''.
  index.insert(make("p02"));
  CHECK(sql_text(path, "SELECT address_hash FROM sessions WHERE id = 2").empty());
}

TEST_CASE("an index made before the address hash gains its column, empty for the sessions it holds") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  const Session old = make("p01");
  {
    SessionIndex index(path);
    index.insert(old);
  }
  // The table as an earlier manager left it: every column but address_hash.
  sql_text(path, "ALTER TABLE sessions DROP COLUMN address_hash");
  REQUIRE(sql_text(path, "SELECT COUNT(*) FROM pragma_table_info('sessions') WHERE name = 'address_hash'") == "0");
  SessionIndex reopened(path);
  CHECK(sql_text(path, "SELECT COUNT(*) FROM pragma_table_info('sessions') WHERE name = 'address_hash'") == "1");
  const auto back = reopened.find_by_token(old.token);
  REQUIRE(back);
  CHECK(back->address_hash.empty());
  Session next = make("p02");
  next.address_hash = "00112233aabbccdd";
  next.id = reopened.insert(next);
  CHECK(reopened.find_by_token(next.token)->address_hash == "00112233aabbccdd");
}

TEST_CASE("a session's ROS namespace and robot control are written with the row and read back") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  SessionIndex index(path);
  Session s = make("p01");
  s.ros_namespace = "/rfbsim/s_1";
  s.robot_control = "external";
  s.id = index.insert(s);
  s.state = SessionState::kRunning;
  index.update(s);
  const auto back = index.find_by_token(s.token);
  REQUIRE(back);
  CHECK(back->ros_namespace == "/rfbsim/s_1");
  CHECK(back->robot_control == "external");
  CHECK(sql_text(path, "SELECT ros_namespace || ' ' || robot_control FROM sessions WHERE id = 1") ==
        "/rfbsim/s_1 external");
  // Without ROS or a robot: ''.
  index.insert(make("p02"));
  CHECK(sql_text(path, "SELECT ros_namespace || robot_control FROM sessions WHERE id = 2").empty());
}

TEST_CASE("an index made before ROS gains its columns, empty for the sessions it holds") {
  ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  const Session old = make("p01");
  {
    SessionIndex index(path);
    index.insert(old);
  }
  // The table as the manager before issue 20 left it.
  sql_text(path, "ALTER TABLE sessions DROP COLUMN ros_namespace");
  sql_text(path, "ALTER TABLE sessions DROP COLUMN robot_control");
  REQUIRE(sql_text(path, "SELECT COUNT(*) FROM pragma_table_info('sessions') WHERE name LIKE 'ro%'") == "0");
  SessionIndex reopened(path);
  CHECK(sql_text(path, "SELECT COUNT(*) FROM pragma_table_info('sessions') WHERE name IN ('ros_namespace', "
                       "'robot_control')") == "2");
  const auto back = reopened.find_by_token(old.token);
  REQUIRE(back);
  CHECK(back->ros_namespace.empty());
  CHECK(back->robot_control.empty());
  Session next = make("p02");
  next.ros_namespace = "/lab/s_2";
  next.robot_control = "builtin";
  reopened.insert(next);
  const auto again = reopened.find_by_token(next.token);
  REQUIRE(again);
  CHECK(again->ros_namespace == "/lab/s_2");
  CHECK(again->robot_control == "builtin");
}
