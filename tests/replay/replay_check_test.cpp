// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's check on sessions recorded in-process with a scripted participant: the outcome and its tick
// come out the same; a log from another version or build, or one whose scenario or map changed, is refused
// (and replayed with --force); a tampered trajectory is caught at its line; bad input is a clear error.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "file_text.hpp"
#include "record/session_log.hpp"
#include "replay_fixtures.hpp"

using namespace rfbsim;
using rfbsim::test::contains;
using nlohmann::json;

namespace {

json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

void write_json(const std::filesystem::path& file, const json& doc) {
  std::ofstream out(file, std::ios::trunc);
  out << doc.dump(2) << '\n';
}

// The lab, a viewer from tick 30, keys now and then, ended by the time limit (3 s) and its grace (15 s).
test::Recording record_lab_timeout(const std::filesystem::path& dir, const std::string& scenario = "lab") {
  test::RecordSpec spec;
  spec.scenario = scenario;
  spec.time_limit = 3.0;
  spec.connect_tick = 30;
  spec.max_ticks = 60 * 60;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 40) study.key('w', true, 1);
    if (tick == 130) study.key('d', true, 1);
    if (tick == 160) study.key('d', false, 1);
    if (tick == 400) study.key('w', false, 1);
    if (tick == 500) study.pointer(10, 20, 1, 1);
  };
  return record_session(spec, dir);
}

// A short lab session ended by a signal at tick 240: enough for the checks on provenance and tampering.
test::Recording record_lab_short(const std::filesystem::path& dir, const std::string& scenario = "lab",
                                 std::optional<std::uint64_t> seed = std::nullopt) {
  test::RecordSpec spec;
  spec.scenario = scenario;
  spec.seed = seed;
  spec.max_ticks = 240;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 10) study.key('w', true, 1);
    if (tick == 200) study.key('w', false, 1);
  };
  return record_session(spec, dir);
}

}  // namespace

TEST_CASE("the replay of a scripted tutorial session reproduces its poses, task steps and outcome tick") {
  const auto dir = test::fresh_dir("tutorial");
  const test::Recording recording = test::record_tutorial(dir);
  REQUIRE(recording.outcome == sim::TaskOutcome::Completed);
  REQUIRE(recording.outcome_tick.has_value());

  const auto out = test::fresh_dir("tutorial_replay");
  const test::ReplayRun run = test::run_replay({dir.string(), "--out-dir", out.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log"));
  CHECK(contains(run.output, "outcome matches: completed at tick " + std::to_string(*recording.outcome_tick)));
  const sim::SessionMeta replayed = sim::read_session(out).meta;
  CHECK(replayed.outcome == "completed");
  REQUIRE(replayed.completion.has_value());
  CHECK(replayed.completion->tick == *recording.outcome_tick);
  CHECK(replayed.completion->code == "OK-1");
  CHECK(replayed.end_tick == recording.end_tick);
  CHECK(replayed.tasks_done.size() == 4);
  CHECK(test::read_lines(out / "trajectories.csv") == test::read_lines(dir / "trajectories.csv"));
}

TEST_CASE("the replay of a lab session that timed out reproduces the timeout at its tick") {
  const auto dir = test::fresh_dir("lab_timeout");
  const test::Recording recording = record_lab_timeout(dir);
  REQUIRE(recording.outcome == sim::TaskOutcome::Timeout);
  REQUIRE(recording.outcome_tick == 30 + 180);

  const test::ReplayRun run = test::run_replay({dir.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log"));
  CHECK(contains(run.output, "outcome matches: timeout at tick 210"));
  // Without --out-dir the replay's own data went into a temporary folder, and is gone.
  CHECK_FALSE(contains(run.output, "the replay's session data"));
}

TEST_CASE("a session whose viewer left and another came back replays with the same poses and outcome") {
  // As sim_rfb records it: the leaver's held keys released by librfbsim (client 0), then the disconnect;
  // later a new viewer (the participant reloaded the page) walks on until the time limit.
  const auto dir = test::fresh_dir("left_and_back");
  test::RecordSpec spec;
  spec.time_limit = 4.0;
  spec.connect_tick = 12;
  spec.max_ticks = 60 * 60;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 20) study.key('w', true, 1);
    if (tick == 100) {
      study.key('w', false, 0);
      study.client_disconnected(1, "0123456789abcdef", true);
    }
    if (tick == 160) study.client_connected(2, "fedcba9876543210", true);
    if (tick == 170) study.key('a', true, 2);
    if (tick == 200) study.key('a', false, 2);
  };
  const test::Recording recording = test::record_session(spec, dir);
  REQUIRE(recording.outcome == sim::TaskOutcome::Timeout);

  const test::ReplayRun run = test::run_replay({dir.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log"));
  CHECK(contains(run.output, "outcome matches: timeout at tick " + std::to_string(*recording.outcome_tick)));
}

TEST_CASE("a researcher who watched before the participant came replays with the clock from the participant") {
  // As sim_rfb records it: the watcher's connect carries "role":"watcher" and starts no clock; the
  // participant's, 100 ticks later, does. A replay that took the watcher for the participant would time
  // out 100 ticks early.
  const auto dir = test::fresh_dir("watched_first");
  test::RecordSpec spec;
  spec.time_limit = 3.0;
  spec.connect_tick = 110;
  spec.max_ticks = 60 * 60;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 10) study.client_connected(2, "aaaaaaaaaaaaaaaa", true, sim::ViewerRole::kWatcher);
    if (tick == 120) study.key('w', true, 1);
    if (tick == 200) study.key('w', false, 1);
  };
  const test::Recording recording = test::record_session(spec, dir);
  REQUIRE(recording.outcome == sim::TaskOutcome::Timeout);
  bool watcher_recorded = false;
  for (const auto& event : sim::read_session(dir).events) {
    if (event.type == "client" && event.integer("client") == 2) watcher_recorded = event.text("role") == "watcher";
  }
  REQUIRE(watcher_recorded);

  const test::ReplayRun run = test::run_replay({dir.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log"));
  CHECK(contains(run.output, "outcome matches: timeout at tick " + std::to_string(*recording.outcome_tick)));
}

TEST_CASE("a session cut short by a crash replays to its last trajectory row, and what it has matches") {
  const auto dir = test::fresh_dir("crashed");
  record_lab_short(dir);
  // What a SIGKILL leaves: no end in session.json, the last rows lost and a torn line after the last whole one.
  json session = read_json(dir / "session.json");
  session["ended_at"] = nullptr;
  session["end_tick"] = nullptr;
  session["end_reason"] = nullptr;
  write_json(dir / "session.json", session);
  auto lines = test::read_lines(dir / "trajectories.csv");
  REQUIRE(lines.size() > 20);
  lines.resize(lines.size() - 4);  // the last sample (3 rows) and one row of the one before
  const std::string last_tick = lines.back().substr(0, lines.back().find(','));
  const std::string torn = lines.back().substr(0, 20);
  test::write_lines(dir / "trajectories.csv", lines);
  std::ofstream(dir / "trajectories.csv", std::ios::app) << torn;

  const test::ReplayRun run = test::run_replay({dir.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log: " + std::to_string(lines.size() - 1) + " rows"));
  CHECK(contains(run.output, "the session did not end cleanly (no end_tick): replayed to its last trajectory tick " + last_tick));
}

TEST_CASE("a log whose versions.rfbsim or versions.build differs from this build is refused, and replayed with force") {
  const auto dir = test::fresh_dir("versions");
  record_lab_short(dir);
  for (const char* field : {"rfbsim", "build"}) {
    const auto edited = test::copy_session(dir, std::string("versions_") + field);
    json session = read_json(edited / "session.json");
    session["versions"][field] = std::string("other-") + field;
    write_json(edited / "session.json", session);

    const test::ReplayRun refused = test::run_replay({edited.string()});
    INFO(refused.output);
    CHECK(refused.exit_code == 2);
    CHECK(contains(refused.output, std::string("versions.") + field + " differs: recorded 'other-" + field + "'"));
    CHECK(contains(refused.output, "--force"));
    CHECK_FALSE(contains(refused.output, "poses match"));

    const test::ReplayRun forced = test::run_replay({edited.string(), "--force"});
    INFO(forced.output);
    CHECK(forced.exit_code == 0);  // the same build in truth: the poses match
    CHECK(contains(forced.output, "[sim_replay] warning: --force"));
    CHECK(contains(forced.output, "poses match the log"));

    // The warning is warn: --log-level error leaves it out, and the verdict on stdout stays.
    const test::ReplayRun silent = test::run_replay({edited.string(), "--force", "--log-level", "error"});
    CHECK(silent.exit_code == 0);
    CHECK_FALSE(contains(silent.output, "warning: --force"));
    CHECK(contains(silent.output, "poses match the log"));
  }
}

TEST_CASE("a session whose scenario file or map image changed after the recording is refused, and replayed with force") {
  // The lab copied into a folder of its own, so that the test may change it.
  const auto scenario_dir = test::fresh_dir("own_lab");
  std::filesystem::create_directories(scenario_dir / "maps");
  const std::filesystem::path source = RFBSIM_SCENARIO_DIR;
  std::filesystem::copy_file(source / "lab.yaml", scenario_dir / "lab.yaml");
  std::filesystem::copy_file(source / "maps" / "lab.yaml", scenario_dir / "maps" / "lab.yaml");
  std::filesystem::copy_file(source / "maps" / "lab.pgm", scenario_dir / "maps" / "lab.pgm");
  const auto dir = test::fresh_dir("own_lab_session");
  record_lab_short(dir, (scenario_dir / "lab.yaml").string());
  REQUIRE(test::run_replay({dir.string()}).exit_code == 0);

  SECTION("the scenario file") {
    std::ofstream(scenario_dir / "lab.yaml", std::ios::app) << "# edited after the recording\n";
    const test::ReplayRun refused = test::run_replay({dir.string()});
    INFO(refused.output);
    CHECK(refused.exit_code == 2);
    CHECK(contains(refused.output, "versions.scenario_sha256 differs"));
    CHECK(contains(refused.output, "the scenario file " + std::filesystem::absolute(scenario_dir / "lab.yaml").lexically_normal().string() +
                                       " changed since the recording"));
    const test::ReplayRun forced = test::run_replay({dir.string(), "--force"});
    INFO(forced.output);
    CHECK(forced.exit_code == 0);  // a comment changes no pose
    CHECK(contains(forced.output, "warning: --force: replaying although versions.scenario_sha256 differs"));
  }
  SECTION("the map image") {
    // One byte of the PGM's comment line ("P5\n# lab: ..."): another file, the same map.
    const auto pgm = scenario_dir / "maps" / "lab.pgm";
    std::string bytes;
    {
      std::ifstream in(pgm, std::ios::binary);
      std::stringstream whole;
      whole << in.rdbuf();
      bytes = whole.str();
    }
    REQUIRE(bytes.rfind("P5\n# ", 0) == 0);
    bytes[5] = bytes[5] == 'x' ? 'y' : 'x';
    std::ofstream(pgm, std::ios::binary | std::ios::trunc) << bytes;
    const test::ReplayRun refused = test::run_replay({dir.string()});
    INFO(refused.output);
    CHECK(refused.exit_code == 2);
    CHECK(contains(refused.output, "versions.map_sha256 differs"));
    CHECK(test::run_replay({dir.string(), "--force"}).exit_code == 0);
  }
}

TEST_CASE("a scenario whose crowd has a seed of its own replays with the crowd it was recorded with") {
  // The lab with `crowd: seed: 7`, run without a seed override: the pedestrian's draws come from 7, while
  // session.json's `seed` is the scenario's master seed (1). The replay must rebuild the same crowd.
  const auto scenario_dir = test::fresh_dir("crowd_seed_lab");
  std::filesystem::create_directories(scenario_dir / "maps");
  const std::filesystem::path source = RFBSIM_SCENARIO_DIR;
  std::filesystem::copy_file(source / "maps" / "lab.yaml", scenario_dir / "maps" / "lab.yaml");
  std::filesystem::copy_file(source / "maps" / "lab.pgm", scenario_dir / "maps" / "lab.pgm");
  auto yaml = test::read_lines(source / "lab.yaml");
  const auto count = std::find(yaml.begin(), yaml.end(), "  count: 1");
  REQUIRE(count != yaml.end());
  yaml.insert(count + 1, "  seed: 7");
  test::write_lines(scenario_dir / "lab.yaml", yaml);
  const auto dir = test::fresh_dir("crowd_seed_session");
  record_lab_short(dir, (scenario_dir / "lab.yaml").string());
  CHECK_FALSE(read_json(dir / "session.json")["parameters"].contains("seed"));

  const test::ReplayRun run = test::run_replay({dir.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(contains(run.output, "poses match the log"));

  // --seed with the file's own master seed still replaces the crowd's seed; the log says it was given.
  const auto given = test::fresh_dir("crowd_seed_given");
  record_lab_short(given, (scenario_dir / "lab.yaml").string(), 1);
  CHECK(read_json(given / "session.json")["parameters"]["seed"] == "1");
  CHECK(test::read_lines(given / "trajectories.csv") != test::read_lines(dir / "trajectories.csv"));
  const test::ReplayRun given_run = test::run_replay({given.string()});
  INFO(given_run.output);
  CHECK(given_run.exit_code == 0);
  CHECK(contains(given_run.output, "poses match the log"));

  // A seed parameter that is not a 64-bit decimal is bad data: a clear refusal.
  json session = read_json(given / "session.json");
  session["parameters"]["seed"] = "12x";
  write_json(given / "session.json", session);
  const test::ReplayRun bad = test::run_replay({given.string()});
  INFO(bad.output);
  CHECK(bad.exit_code == 2);
  CHECK(contains(bad.output, "parameters.seed"));
  CHECK(contains(bad.output, "12x"));
}

TEST_CASE("a trajectory with one number changed fails the check with the line that differs") {
  const auto dir = test::fresh_dir("tamper");
  record_lab_short(dir);
  const auto tampered = test::copy_session(dir, "tampered");
  auto lines = test::read_lines(tampered / "trajectories.csv");
  REQUIRE(lines.size() > 100);
  // Line 100 (1-based): its x, one digit changed.
  std::string& row = lines[99];
  const std::string original = row;
  const std::size_t x_start = [&] {
    std::size_t at = 0;
    for (int comma = 0; comma < 4; ++comma) at = row.find(',', at) + 1;
    return at;
  }();
  const std::size_t digit = row.find(',', x_start) - 1;
  row[digit] = row[digit] == '5' ? '6' : '5';
  test::write_lines(tampered / "trajectories.csv", lines);

  const test::ReplayRun run = test::run_replay({tampered.string()});
  INFO(run.output);
  CHECK(run.exit_code == 3);
  CHECK(contains(run.output, "the replay differs from the log at trajectories.csv line 100"));
  CHECK(contains(run.output, "column x"));
  CHECK(contains(run.output, "recorded: " + row));
  CHECK(contains(run.output, "replayed: " + original));
  CHECK_FALSE(contains(run.output, "poses match"));
}

TEST_CASE("a missing folder, a broken session.json or a bad command line is a clear error with exit status 2") {
  SECTION("a missing folder") {
    const auto missing = test::fresh_dir("does_not_exist");
    const test::ReplayRun run = test::run_replay({missing.string()});
    CHECK(run.exit_code == 2);
    CHECK(contains(run.output, missing.string() + ": no such folder"));
  }
  SECTION("a broken session.json") {
    const auto dir = test::fresh_dir("broken");
    record_lab_short(dir);
    std::ofstream(dir / "session.json", std::ios::trunc) << "{\"format\": \"rfbsim-session/1\", \"uid\": ";
    const test::ReplayRun run = test::run_replay({dir.string()});
    INFO(run.output);
    CHECK(run.exit_code == 2);
    CHECK(contains(run.output, "cannot read the session: " + (dir / "session.json").string() + ": not JSON"));
  }
  SECTION("a session.json without its seed") {
    const auto dir = test::fresh_dir("no_seed");
    record_lab_short(dir);
    json session = read_json(dir / "session.json");
    session.erase("seed");
    write_json(dir / "session.json", session);
    const test::ReplayRun run = test::run_replay({dir.string()});
    INFO(run.output);
    CHECK(run.exit_code == 2);
    CHECK(contains(run.output, "missing key 'seed'"));
  }
  SECTION("a bad command line") {
    CHECK(test::run_replay({}).exit_code == 2);
    const test::ReplayRun both = test::run_replay({"x", "--check-only", "--video", "x.mp4"});
    CHECK(both.exit_code == 2);
    CHECK(contains(both.output, "not both"));
    CHECK(test::run_replay({"x", "--view", "side"}).exit_code == 2);
    CHECK(test::run_replay({"--help"}).exit_code == 0);
  }
  SECTION("an --out-dir that already holds session data") {
    const auto dir = test::fresh_dir("out_dir_taken");
    record_lab_short(dir);
    const test::ReplayRun run = test::run_replay({dir.string(), "--out-dir", dir.string()});
    CHECK(run.exit_code == 2);
    CHECK(contains(run.output, "is the session's own folder"));
  }
}
