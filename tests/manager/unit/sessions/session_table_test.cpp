// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <stdexcept>

#include "sessions/session_table.hpp"

using rfbsim::manager::Session;
using rfbsim::manager::SessionState;
using rfbsim::manager::SessionTable;

namespace {

// 32 hex digits that differ per id.
std::string token_of(std::int64_t id) {
  const std::string digits = std::to_string(id);
  return std::string(32 - digits.size(), 'a') + digits;
}

// A live session whose id, uid, token and pid all derive from `id`.
Session live(std::int64_t id, SessionState state = SessionState::kRunning) {
  Session session;
  session.id = id;
  session.uid = "p" + std::to_string(id);
  session.token = token_of(id);
  session.pid = static_cast<pid_t>(1000 + id);
  session.state = state;
  return session;
}

}  // namespace

TEST_CASE("an empty table finds nothing") {
  SessionTable table(2);
  CHECK(table.capacity() == 2);
  CHECK(table.size() == 0);
  CHECK_FALSE(table.full());
  CHECK(table.by_id(1) == nullptr);
  CHECK(table.by_uid("p1") == nullptr);
  CHECK(table.by_token(token_of(1)) == nullptr);
  CHECK(table.by_pid(1001) == nullptr);
  CHECK(table.all().empty());
}

TEST_CASE("an added session is found by id, uid, token and pid") {
  SessionTable table(3);
  Session& added = table.add(live(1));
  table.add(live(2, SessionState::kStarting));
  CHECK(table.size() == 2);
  CHECK(added.uid == "p1");
  CHECK(table.by_id(1) == &added);
  CHECK(table.by_uid("p1") == &added);
  CHECK(table.by_token(token_of(1)) == &added);
  CHECK(table.by_pid(1001) == &added);
  REQUIRE(table.by_uid("p2") != nullptr);
  CHECK(table.by_uid("p2")->id == 2);
  CHECK(table.by_pid(1002)->uid == "p2");
  CHECK(table.by_uid("p3") == nullptr);
  CHECK(table.by_pid(1003) == nullptr);
  CHECK(table.by_id(3) == nullptr);
}

TEST_CASE("a reference from add stays valid and writes through") {
  SessionTable table(3);
  Session& first = table.add(live(1));
  for (int id = 2; id <= 3; ++id) table.add(live(id));
  first.port = 5901;
  first.state = SessionState::kEnding;
  CHECK(table.by_id(1)->port == 5901);
  CHECK(table.by_uid("p1")->state == SessionState::kEnding);
}

TEST_CASE("the table is full at its capacity and add throws then") {
  SessionTable table(2);
  table.add(live(1));
  CHECK_FALSE(table.full());
  table.add(live(2));
  CHECK(table.full());
  CHECK_THROWS_AS(table.add(live(3)), std::logic_error);
  CHECK(table.size() == 2);
  CHECK(table.by_id(3) == nullptr);
}

TEST_CASE("a table of capacity zero is always full") {
  SessionTable table(0);
  CHECK(table.full());
  CHECK_THROWS_AS(table.add(live(1)), std::logic_error);
}

TEST_CASE("add refuses a duplicate id, uid or token") {
  SessionTable table(5);
  table.add(live(1));
  SECTION("same uid") {
    Session session = live(2);
    session.uid = "p1";
    CHECK_THROWS_AS(table.add(session), std::logic_error);
  }
  SECTION("same token") {
    Session session = live(2);
    session.token = token_of(1);
    CHECK_THROWS_AS(table.add(session), std::logic_error);
  }
  SECTION("same id") {
    Session session = live(2);
    session.id = 1;
    CHECK_THROWS_AS(table.add(session), std::logic_error);
  }
  CHECK(table.size() == 1);
  CHECK(table.by_id(1)->uid == "p1");
}

TEST_CASE("add refuses a session that is not live") {
  SessionTable table(5);
  for (const SessionState state : {SessionState::kFinished, SessionState::kCrashed, SessionState::kFailed,
                                   SessionState::kExpired, SessionState::kInterrupted}) {
    CHECK_THROWS_AS(table.add(live(1, state)), std::logic_error);
  }
  CHECK(table.size() == 0);
  table.add(live(1, SessionState::kEnding));
  CHECK(table.size() == 1);
}

TEST_CASE("remove frees the slot and forgets the session") {
  SessionTable table(2);
  table.add(live(1));
  table.add(live(2));
  REQUIRE(table.full());
  table.remove(1);
  CHECK_FALSE(table.full());
  CHECK(table.size() == 1);
  CHECK(table.by_id(1) == nullptr);
  CHECK(table.by_uid("p1") == nullptr);
  CHECK(table.by_pid(1001) == nullptr);
  table.add(live(3));
  CHECK(table.full());
  SECTION("the same uid may come back once removed") {
    table.remove(3);
    Session again = live(4);
    again.uid = "p1";
    table.add(again);
    CHECK(table.by_uid("p1")->id == 4);
  }
  SECTION("removing an id that is not there does nothing") {
    table.remove(42);
    CHECK(table.size() == 2);
  }
}

TEST_CASE("all lists the live sessions oldest first") {
  SessionTable table(4);
  table.add(live(7));
  table.add(live(2));
  table.add(live(12));
  const auto sessions = table.all();
  REQUIRE(sessions.size() == 3);
  CHECK(sessions[0]->id == 2);
  CHECK(sessions[1]->id == 7);
  CHECK(sessions[2]->id == 12);
}
