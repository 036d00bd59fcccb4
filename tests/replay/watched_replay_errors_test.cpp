// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb --replay given what it cannot replay: a missing folder, a folder that is not a session, a torn or
// corrupt log, a watcher's data folder inside the recording. Each is one clear line and exit status 2, before
// anything listens, and nothing is written into the folder given.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <fstream>

#include "file_text.hpp"
#include "replay_fixtures.hpp"
#include "sim_process.hpp"

using namespace rfbsim;

namespace {

// sim_rfb --replay `dir` with `extra` arguments, run to its exit.
test::ExitResult replay_of(const std::filesystem::path& dir, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"--replay", dir.string(), "--port", "0", "--rfb-only"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_to_exit(test::sim_rfb_path(), args, std::chrono::seconds(60));
}

// Checks that `result` is a clean exit 2 whose output names `words`, and no ready line.
void check_refused(const test::ExitResult& result, const std::string& words) {
  INFO(result.output);
  REQUIRE(WIFEXITED(result.status));
  CHECK(WEXITSTATUS(result.status) == 2);
  CHECK(result.output.find("sim_rfb: replay: ") != std::string::npos);
  CHECK(result.output.find(words) != std::string::npos);
  CHECK(result.output.find("sim_rfb ready") == std::string::npos);
}

// A short recording of the still lab, made in-process as sim_rfb records.
std::filesystem::path short_recording(const std::string& name) {
  const auto dir = test::fresh_dir(name);
  test::RecordSpec spec;
  spec.scenario = RFBSIM_STILL_SCENARIO;
  spec.max_ticks = 120;
  test::record_session(spec, dir);
  return dir;
}

}  // namespace

TEST_CASE("sim_rfb --replay of a folder that does not exist, or is not a session, exits 2 naming it") {
  const auto missing = test::fresh_dir("watched_missing");
  check_refused(replay_of(missing), missing.string() + ": no such folder");
  CHECK_FALSE(std::filesystem::exists(missing));

  const auto empty = test::fresh_dir("watched_not_a_session");
  std::filesystem::create_directories(empty);
  check_refused(replay_of(empty), "session.json");
  CHECK(std::filesystem::is_empty(empty));
  std::filesystem::remove_all(empty);
}

TEST_CASE("sim_rfb --replay of a torn session.json or a corrupt log exits 2 naming the file") {
  const auto recorded = short_recording("watched_source");

  const auto torn = test::copy_session(recorded, "watched_torn_json");
  {
    const std::vector<std::string> lines = test::read_lines(torn / "session.json");
    REQUIRE(lines.size() > 4);
    std::ofstream out(torn / "session.json", std::ios::trunc);
    for (std::size_t i = 0; i < lines.size() / 2; ++i) out << lines[i] << "\n";  // cut off mid-document
  }
  check_refused(replay_of(torn), "session.json");

  const auto corrupt = test::copy_session(recorded, "watched_corrupt_csv");
  std::vector<std::string> rows = test::read_lines(corrupt / "trajectories.csv");
  REQUIRE(rows.size() > 3);
  rows[2] = "12,not a number,avatar";
  test::write_lines(corrupt / "trajectories.csv", rows);
  check_refused(replay_of(corrupt), "trajectories.csv");

  const auto bad_events = test::copy_session(recorded, "watched_corrupt_events");
  std::vector<std::string> events = test::read_lines(bad_events / "events.jsonl");
  REQUIRE(!events.empty());
  events.insert(events.begin(), "{\"tick\":");
  test::write_lines(bad_events / "events.jsonl", events);
  check_refused(replay_of(bad_events), "events.jsonl");

  for (const auto& dir : {recorded, torn, corrupt, bad_events}) std::filesystem::remove_all(dir);
}

TEST_CASE("sim_rfb --replay refuses a watcher's data folder inside the recording") {
  const auto recorded = short_recording("watched_inside");
  const auto recorded_meta = test::file_text(recorded / "session.json");
  check_refused(replay_of(recorded, {"--data-dir", recorded.string()}), "inside the recording");
  check_refused(replay_of(recorded, {"--data-dir", (recorded / "w").string()}), "inside the recording");
  CHECK_FALSE(std::filesystem::exists(recorded / "w"));
  CHECK(test::file_text(recorded / "session.json") == recorded_meta);
  std::filesystem::remove_all(recorded);
}
