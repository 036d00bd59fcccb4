// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay and the video condition (issue 33): a watcher's folder holds only its session.json (it walked
// nowhere), so sim_replay refuses it with exit 2 and one line naming the session it watched, found by its folder
// or by --data-dir --uid, before it looks for a trajectories.csv; the watcher_session peek it relies on.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "file_text.hpp"
#include "replay_fixtures.hpp"
#include "watcher_session.hpp"

using namespace rfbsim;
using rfbsim::test::contains;
using rfbsim::test::write_text;
using nlohmann::json;

namespace {

// A watcher's folder as sim_rfb --replay writes it (docs/data.md), with sim_manager's session.log beside it.
std::filesystem::path watcher_folder(const std::filesystem::path& dir, const json& yoked_to) {
  const json doc = {{"kind", "replay"},
                    {"condition", "video"},
                    {"uid", "pB"},
                    {"yoked_to", yoked_to},
                    {"yoked_to_uid_hash", "3f2a"},
                    {"scenario", "lab"},
                    {"camera", "third_person"},
                    {"replay_of", {{"uid_hash", "3f2a"}, {"scenario", "lab"}, {"seed", "42"},
                                   {"started_at", "2026-11-29T10:00:00.000Z"}, {"end_tick", 1800},
                                   {"end_reason", "completed"}, {"outcome", "completed"}}},
                    {"versions", {{"rfbsim", "0.1.0"}, {"build", "test"}}},
                    {"started_at", "2026-11-29T10:05:00.000Z"},
                    {"ended_at", "2026-11-29T10:05:33.000Z"},
                    {"end_tick", 1800},
                    {"end_reason", "watched"},
                    {"outcome", "watched"},
                    {"viewers", 1}};
  write_text(dir / "session.json", doc.dump(2) + "\n");
  write_text(dir / "session.log", "[sim_rfb] watching\n");
  return dir;
}

}  // namespace

TEST_CASE("sim_replay refuses a watcher's folder with one line naming the session it watched") {
  const auto root = test::fresh_dir("watcher_refused");
  const auto yoked = watcher_folder(root / "sessions" / "14-pB", 12);
  const test::ReplayRun run = test::run_replay({yoked.string(), "-q"});
  CHECK(run.exit_code == 2);
  CHECK(run.output == "sim_replay: " + yoked.string() +
                          " is a watcher's session (condition video) of session 12: replay its source instead\n");

  // sim_rfb --replay run by hand names no source session.
  const auto by_hand = watcher_folder(test::fresh_dir("watcher_by_hand"), nullptr);
  const test::ReplayRun unyoked = test::run_replay({by_hand.string(), "-q"});
  CHECK(unyoked.exit_code == 2);
  CHECK(contains(unyoked.output,
                 "sim_replay: " + by_hand.string() +
                     " is a watcher's session (condition video) of a recording: replay its source instead\n"));
  CHECK_FALSE(contains(unyoked.output, "trajectories.csv"));

  // Found by its uid across the data folders, it is refused alike (and --video writes nothing).
  const test::ReplayRun found = test::run_replay(
      {"--data-dir", root.string(), "--uid", "pB", "--video", (root / "b.mp4").string(), "--log-level", "warn"});
  CHECK(found.exit_code == 2);
  CHECK(found.output == "sim_replay: " + yoked.string() +
                            " is a watcher's session (condition video) of session 12: replay its source instead\n");
  CHECK_FALSE(std::filesystem::exists(root / "b.mp4"));
}

TEST_CASE("a session.json is a watcher's by its condition or its kind, anything else is left to the strict reader") {
  const auto root = test::fresh_dir("watcher_peek");
  const auto peek = [&](const std::string& text) {
    write_text(root / "session.json", text);
    return tools::peek_session_kind(root);
  };
  const tools::SessionKind video = peek(R"({"condition": "video", "yoked_to": 7})");
  CHECK(video.video);
  CHECK(video.yoked_to == std::optional<std::int64_t>(7));
  CHECK(peek(R"({"kind": "replay", "yoked_to": null})").video);
  CHECK_FALSE(peek(R"({"kind": "replay", "yoked_to": null})").yoked_to);
  CHECK_FALSE(peek(R"({"format": "rfbsim-session/1", "uid": "a"})").video);  // before issue 33: interactive
  CHECK_FALSE(peek(R"({"condition": "interactive", "kind": "session"})").video);
  CHECK_FALSE(peek("{\"condition\": \"vid").video);  // torn: the strict reader says what is wrong
  const tools::SessionKind unknown = peek(R"({"condition": "audio"})");
  CHECK_FALSE(unknown.video);
  CHECK(unknown.unknown_condition == "audio");
  std::filesystem::remove(root / "session.json");
  CHECK_FALSE(tools::peek_session_kind(root).video);
  CHECK(tools::watched_source(12) == "session 12");
  CHECK(tools::watched_source(std::nullopt) == "a recording");
}
