// SPDX-License-Identifier: GPL-2.0-or-later
// manager.json read for the report: the manager's own records give the state and the spent time to the
// millisecond, its times are parsed strictly, and broken, hostile or mangled files are a ManagerRecordError
// naming the file and the key, never a crash.
#include <catch2/catch.hpp>

#include <random>
#include <string>

#include "manager_record.hpp"
#include "session_files.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

const std::filesystem::path kFile = "DATA/sessions/3-p1/manager.json";

// The message parse_manager_record throws for `text`, or "" when it parses.
std::string error_of(const std::string& text) {
  try {
    parse_manager_record(text, kFile);
  } catch (const ManagerRecordError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a spent session's record gives its state and the time from creation to the first picture") {
  const ManagerRecord r = parse_manager_record(manager_json("p1", "finished", 1500), kFile);
  CHECK(r.uid == "p1");
  CHECK(r.state == "finished");
  REQUIRE(r.spent_after.has_value());
  CHECK(*r.spent_after == 1.5);
  CHECK_FALSE(r.data_incomplete.has_value());
}

TEST_CASE("an abandoned session's record has no spent time, and a data failure keeps its reason") {
  const ManagerRecord abandoned = parse_manager_record(manager_json("p1", "abandoned"), kFile);
  CHECK(abandoned.state == "abandoned");
  CHECK(abandoned.detail == "no browser connected for 60 s");
  CHECK_FALSE(abandoned.spent_after.has_value());

  const ManagerRecord failed = parse_manager_record(manager_json("p2", "ended", 61001, "ENOSPC"), kFile);
  CHECK(*failed.spent_after == 61.001);
  CHECK(failed.data_incomplete == std::optional<std::string>("ENOSPC"));
}

TEST_CASE("every state the manager writes is accepted") {
  for (const char* state : {"starting", "running", "ending", "finished", "expired", "idle", "ended", "shutdown",
                            "crashed", "failed", "interrupted", "abandoned"}) {
    INFO(state);
    CHECK(error_of(manager_json("p1", state)).empty());
  }
}

TEST_CASE("UTC times are parsed to the millisecond, and anything else is refused") {
  CHECK(parse_utc_millis("1970-01-01T00:00:00Z") == 0);
  CHECK(parse_utc_millis("2026-11-25T10:00:00.300Z") == 1795600800300LL);
  CHECK(parse_utc_millis("2026-11-25T10:00:00.3Z") == 1795600800300LL);
  CHECK(parse_utc_millis("2026-11-25T10:00:00.300999999Z") == 1795600800300LL);
  CHECK(parse_utc_millis("2000-02-29T23:59:59.999Z") == 951868799999LL);  // a leap day
  for (const char* bad : {"", "2026-11-25", "2026-11-25 10:00:00Z", "2026-11-25T10:00:00", "2026-11-25T10:00:00.Z",
                          "2026-11-25T10:00:00+01:00", "2026-11-25T10:00:00.3000000000Z", "2026-02-29T00:00:00Z",
                          "2026-13-01T00:00:00Z", "2026-11-25T24:00:00Z", "2026-11-25T10:60:00Z",
                          "2026-11-25T10:00:00ZZ", "-026-11-25T10:00:00Z", "2026-11-25T10:00:00.-1Z"}) {
    INFO(bad);
    CHECK_FALSE(parse_utc_millis(bad).has_value());
  }
}

TEST_CASE("a broken record is an error naming the file and what is wrong") {
  const std::string file = kFile.string() + ": ";
  CHECK_THAT(error_of(""), Catch::StartsWith(file + "not JSON"));
  CHECK_THAT(error_of("{\"state\": \"finished\""), Catch::StartsWith(file + "not JSON"));
  CHECK(error_of("[1, 2]") == file + "expected a JSON object");
  CHECK(error_of("{}") == file + "key 'uid': missing");
  CHECK(error_of(R"({"uid": "p1"})") == file + "key 'state': missing");
  CHECK(error_of(R"({"uid": 7, "state": "finished"})") == file + "key 'uid': expected a string");
  CHECK(error_of(R"({"uid": "p1", "state": "gone"})") == file + "key 'state': unknown state 'gone'");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "spent_at": null})") == file + "key 'created_at': missing");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "created_at": "2026-11-25T10:00:00.000Z"})") ==
        file + "key 'spent_at': missing");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "created_at": "yesterday", "spent_at": null})") ==
        file + "key 'created_at': expected an ISO 8601 UTC time, got 'yesterday'");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "created_at": "2026-11-25T10:00:00.000Z", "spent_at": 5})") ==
        file + "key 'spent_at': expected a string");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "created_at": "2026-11-25T10:00:01.000Z",
                     "spent_at": "2026-11-25T10:00:00.000Z"})") == file + "spent_at is before created_at");
  CHECK(error_of(R"({"uid": "p1", "state": "abandoned", "created_at": "2026-11-25T10:00:00.000Z",
                     "spent_at": "2026-11-25T10:00:01.000Z"})") ==
        file + "state 'abandoned' with a spent_at: an abandoned link is unspent");
  CHECK(error_of(R"({"uid": "p1", "state": "finished", "created_at": "2026-11-25T10:00:00.000Z", "spent_at": null,
                     "data_incomplete": {"reason": "x"}})") == file + "key 'data_incomplete': expected a string");
}

TEST_CASE("mangled records either parse or are a ManagerRecordError") {
  // Every byte position overwritten, dropped or cut short with a fixed seed: nothing else may come out.
  const std::string good = manager_json("p1", "finished", 1500, "ENOSPC");
  std::mt19937 random(17);
  std::size_t parsed = 0, refused = 0;
  for (std::size_t at = 0; at < good.size(); ++at) {
    for (const int kind : {0, 1, 2}) {
      std::string mangled = good;
      if (kind == 0) mangled[at] = static_cast<char>(random() & 0xff);
      if (kind == 1) mangled.erase(at, 1);
      if (kind == 2) mangled.resize(at);
      error_of(mangled).empty() ? ++parsed : ++refused;  // anything but ManagerRecordError fails the test
    }
  }
  CHECK(parsed + refused == 3 * good.size());
  CHECK(refused > good.size());
}

TEST_CASE("read_manager_record: none without the file, an error for a folder, a huge or an empty file") {
  ScratchDir scratch;
  CHECK_FALSE(read_manager_record(scratch.path()).has_value());

  write_text(scratch.path() / "a" / "manager.json", manager_json("p1", "abandoned"));
  CHECK(read_manager_record(scratch.path() / "a")->state == "abandoned");

  std::filesystem::create_directories(scratch.path() / "b" / "manager.json");
  CHECK_THROWS_WITH(read_manager_record(scratch.path() / "b"),
                    (scratch.path() / "b" / "manager.json").string() + ": not a regular file");

  write_text(scratch.path() / "c" / "manager.json", std::string(70000, ' '));
  CHECK_THROWS_WITH(read_manager_record(scratch.path() / "c"),
                    (scratch.path() / "c" / "manager.json").string() + ": 70000 bytes: too large for a manager.json");

  write_text(scratch.path() / "d" / "manager.json", "");
  CHECK_THROWS_AS(read_manager_record(scratch.path() / "d"), ManagerRecordError);
}
