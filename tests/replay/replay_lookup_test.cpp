// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay across hosts: `--data-dir DIR... --uid UID | --session ID [--host HOST]` finds the one session
// it names in several hosts' data folders or the shared store (a copy found twice is one session), says so
// when there is none or several, and replays the one it found like a SESSION_DIR.
#include <catch2/catch.hpp>

#include <fstream>
#include <nlohmann/json.hpp>

#include "file_text.hpp"
#include "replay_cli.hpp"
#include "replay_fixtures.hpp"
#include "session_lookup.hpp"

using namespace rfbsim;
using rfbsim::test::contains;
using rfbsim::test::write_text;
using namespace rfbsim::replay;
using nlohmann::json;

namespace {

// A folder that the catalog takes for a session: a session.json of `uid`, and a manager.json naming `host`.
void fake_session(const std::filesystem::path& dir, const std::string& uid, const std::optional<std::string>& host) {
  write_text(dir / "session.json", json{{"format", "rfbsim-session/1"}, {"uid", uid}, {"started_at", dir.string()}}.dump());
  if (host) write_text(dir / "manager.json", json{{"host", *host}}.dump());
}

// A copy of a session folder's files (and manager.json, when there is one) at `to`.
void copy_folder(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::filesystem::create_directories(to.parent_path());
  std::filesystem::copy(from, to, std::filesystem::copy_options::recursive);
}

}  // namespace

TEST_CASE("the command line finds a session by uid or id under --data-dir folders, or takes its folder") {
  CliError error;
  const auto found = parse_cli({"--data-dir", "h1", "--data-dir=store", "--uid", "p7", "--host", "h2"}, error);
  REQUIRE(found);
  CHECK(found->data_dirs == std::vector<std::filesystem::path>{"h1", "store"});
  CHECK(found->uid == std::optional<std::string>("p7"));
  CHECK(found->host == std::optional<std::string>("h2"));
  CHECK(found->session_dir.empty());
  CHECK(parse_cli({"--data-dir", "d", "--session", "3", "--video", "v.mp4"}, error)->session == "3");

  const auto fails = [](std::vector<std::string> args) {
    CliError e;
    return parse_cli(args, e) ? std::string() : e.message;
  };
  CHECK(fails({"--data-dir", "d"}) == "--data-dir needs --uid UID or --session ID (which session to replay)");
  CHECK(fails({"--data-dir", "d", "--uid", "a", "--session", "1"}) == "--uid and --session: give one of them");
  CHECK(fails({"s", "--data-dir", "d", "--uid", "a"}) ==
        "give SESSION_DIR or --data-dir with --uid or --session, not both");
  CHECK(fails({"s", "--uid", "a"}) ==
        "--uid picks a session under --data-dir folders: give --data-dir DIR (or the SESSION_DIR alone)");
  CHECK(fails({"--data-dir", "d", "--uid"}) == "--uid needs a value");
  // The old form is as it was.
  CHECK(parse_cli({"s"}, error)->session_dir == "s");
  CHECK(fails({}) == "SESSION_DIR is missing");
}

TEST_CASE("lookup_session names the one session of a uid or id across hosts, and lists them when there are more") {
  const auto root = test::fresh_dir("lookup");
  const auto h1 = root / "h1-data", store = root / "store";
  fake_session(h1 / "sessions" / "1-p001", "p001", "h1");
  fake_session(h1 / "sessions" / "2-p002", "p002", "h1");
  fake_session(store / "h2" / "1-p003", "p003", std::nullopt);  // host from the store's layout
  fake_session(store / "h2" / "2-p002", "p002", std::nullopt);  // p002 on two hosts
  copy_folder(h1 / "sessions" / "1-p001", store / "h1" / "1-p001");  // the store's copy: one session

  SECTION("a uid on one host, its copy in the store counted once") {
    const LookupResult r = lookup_session({h1, store}, {"p001", std::nullopt, std::nullopt});
    INFO(r.error);
    REQUIRE(r.found);
    CHECK(r.found->dir == h1 / "sessions" / "1-p001");
    CHECK(r.found->host == "h1");
  }
  SECTION("a uid in the store only") {
    const LookupResult r = lookup_session({h1, store}, {"p003", std::nullopt, std::nullopt});
    REQUIRE(r.found);
    CHECK(r.found->dir == store / "h2" / "1-p003");
    CHECK(r.found->host == "h2");
  }
  SECTION("a uid on two hosts is an error listing both, and --host picks one") {
    const LookupResult r = lookup_session({h1, store}, {"p002", std::nullopt, std::nullopt});
    CHECK_FALSE(r.found);
    CHECK(r.error == "uid 'p002' matches 2 sessions:\n  host h1: " + (h1 / "sessions" / "2-p002").string() +
                         "\n  host h2: " + (store / "h2" / "2-p002").string() +
                         "\nname one with --host HOST (or give its SESSION_DIR)");
    const LookupResult picked = lookup_session({h1, store}, {"p002", std::nullopt, "h2"});
    REQUIRE(picked.found);
    CHECK(picked.found->dir == store / "h2" / "2-p002");
  }
  SECTION("a session by its folder name or the manager's id") {
    CHECK(lookup_session({h1, store}, {std::nullopt, "1-p003", std::nullopt}).found->dir == store / "h2" / "1-p003");
    const LookupResult by_id = lookup_session({h1, store}, {std::nullopt, "1", std::nullopt});
    CHECK_FALSE(by_id.found);  // id 1 on h1 and on h2
    CHECK(contains(by_id.error, "session '1' matches 2 sessions:"));
    CHECK(lookup_session({h1, store}, {std::nullopt, "1", "h2"}).found->dir == store / "h2" / "1-p003");
    CHECK_FALSE(lookup_session({h1}, {std::nullopt, "p001", std::nullopt}).found);  // not a prefix of "1-p001"
  }
  SECTION("nothing found, or a folder that is not there") {
    const LookupResult none = lookup_session({h1, store}, {"p999", std::nullopt, std::nullopt});
    CHECK_FALSE(none.found);
    CHECK(none.error == "no session of uid 'p999' under " + h1.string() + ", " + store.string() +
                            " (4 sessions looked at)");
    const LookupResult missing = lookup_session({h1, root / "gone"}, {"p001", std::nullopt, std::nullopt});
    CHECK(missing.error == (root / "gone").string() + ": no such folder");
  }
}

TEST_CASE("sim_replay --data-dir --uid replays the session it finds across two hosts' folders") {
  const auto root = test::fresh_dir("lookup_replay");
  const auto h1 = root / "h1", store = root / "store";
  // The recorded session lies in the store under h2; h1 holds another participant's.
  test::RecordSpec spec;
  spec.max_ticks = 120;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 10) study.key('w', true, 1);
    if (tick == 100) study.key('w', false, 1);
  };
  test::record_session(spec, store / "h2" / "4-p-replay");  // the fixtures' uid is p-replay
  fake_session(h1 / "sessions" / "1-p-other", "p-other", "h1");

  const test::ReplayRun run = test::run_replay({"--data-dir", h1.string(), "--data-dir", store.string(), "--uid",
                                                "p-replay", "-q"});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  const std::string found = "[sim_replay] session " + (store / "h2" / "4-p-replay").string() + " (host h2)";
  CHECK(contains(run.output, found));
  CHECK(contains(run.output, "poses match the log"));
  // That line is info: --log-level warn leaves it out, and the verdict on stdout stays.
  const test::ReplayRun quiet = test::run_replay(
      {"--data-dir", h1.string(), "--data-dir", store.string(), "--uid", "p-replay", "-q", "--log-level", "warn"});
  CHECK(quiet.exit_code == 0);
  CHECK_FALSE(contains(quiet.output, found));
  CHECK(contains(quiet.output, "poses match the log"));

  // The same uid on h1 as well: ambiguous (exit 2, both listed) until --host says which.
  copy_folder(store / "h2" / "4-p-replay", h1 / "sessions" / "9-p-replay");
  write_text(h1 / "sessions" / "9-p-replay" / "manager.json", json{{"host", "h1"}}.dump());
  const test::ReplayRun both = test::run_replay({"--data-dir", h1.string(), "--data-dir", store.string(), "--uid",
                                                 "p-replay", "-q"});
  CHECK(both.exit_code == 2);
  CHECK(contains(both.output, "uid 'p-replay' matches 2 sessions:"));
  CHECK(test::run_replay({"--data-dir", h1.string(), "--data-dir", store.string(), "--uid", "p-replay", "--host", "h1",
                          "-q"})
            .exit_code == 0);
  CHECK(test::run_replay({"--data-dir", h1.string(), "--uid", "nobody"}).exit_code == 2);
}
