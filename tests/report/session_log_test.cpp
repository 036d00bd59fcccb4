// SPDX-License-Identifier: GPL-2.0-or-later
// The session reader: a written folder reads back whole; torn last lines are dropped; bad content is
// refused with the file, the line and what is wrong; garbage never gets anything but SessionLogError.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>
#include <string>

#include "record/session_log.hpp"
#include "session_files.hpp"
#include "session_metrics.hpp"
#include "session_samples.hpp"
#include "trajectory_plot.hpp"

using namespace rfbsim::report::test;
using rfbsim::sim::AgentKind;
using rfbsim::sim::read_session;
using rfbsim::sim::SessionLogError;

namespace {

// The message read_session throws for `dir`, or "" when it reads.
std::string read_error(const std::filesystem::path& dir) {
  try {
    read_session(dir);
  } catch (const SessionLogError& e) {
    return e.what();
  }
  return "";
}

// Writes the small session, then replaces one of its files.
std::filesystem::path with_file(const ScratchDir& scratch, const std::string& name, const std::string& text) {
  const std::filesystem::path dir = scratch.path() / "s";
  write_session(dir, small_session());
  write_text(dir / name, text);
  return dir;
}

}  // namespace

TEST_CASE("a written session folder reads back with every key of session.json") {
  ScratchDir scratch;
  SessionSpec spec = small_session();
  spec.outcome = "completed";
  spec.events.push_back(event(6, "key", {{"keysym", 0x77}, {"down", true}, {"client", 1}}));
  spec.events.push_back(event(6, "client", {{"event", "connect"}, {"client", 1}, {"address", "0123456789abcdef"},
                                            {"websocket", true}}));
  write_session(scratch.path(), spec);

  const auto log = read_session(scratch.path());
  CHECK(log.meta.uid == "p001");
  CHECK(log.meta.scenario == "lab");
  CHECK(log.meta.parameters.at("crowd") == "1");
  CHECK(log.meta.seed == UINT64_MAX);  // the decimal string holds all 64 bits
  CHECK(log.meta.tick_hz == 60);
  CHECK(log.meta.trajectory_hz == 10);
  CHECK(log.meta.frame_width == 1280);
  CHECK(log.meta.rfbsim_version == "0.1.0");
  REQUIRE(log.meta.agents.size() == 3);
  CHECK(log.meta.agents[1].kind == AgentKind::Robot);
  CHECK(log.meta.agents[1].radius == Approx(0.16));
  REQUIRE(log.meta.tasks.size() == 1);
  CHECK(log.meta.tasks[0].type == "find_robot");
  CHECK(log.meta.time_limit_s == Approx(240.0));
  CHECK(log.meta.success_code == "C1");
  CHECK(log.meta.end_tick == 60u);
  CHECK(log.meta.outcome == "completed");
  CHECK_FALSE(log.meta.completion.has_value());

  CHECK(log.trajectory.size() == 33);
  CHECK(log.trajectory[4].tick == 6);
  CHECK(log.trajectory[4].kind == AgentKind::Robot);
  CHECK(log.trajectory[4].x == Approx(3.0));
  REQUIRE(log.events.size() == 3);
  CHECK(log.events[1].type == "key");
  CHECK(log.events[1].integer("keysym") == 0x77);
  CHECK(log.events[1].flag("down"));
  CHECK(log.events[2].text("address") == "0123456789abcdef");
  CHECK(log.events[2].text("no such key").empty());
  CHECK(log.torn_lines == 0);
}

TEST_CASE("a last line without its newline is a write cut short and is dropped and counted") {
  ScratchDir scratch;
  write_session(scratch.path(), small_session());
  std::ofstream(scratch.path() / "trajectories.csv", std::ios::app) << "66,1.100000,avatar,0,1.0";
  std::ofstream(scratch.path() / "events.jsonl", std::ios::app) << R"({"tick":66,"time":1.1,"ty)";

  const auto log = read_session(scratch.path());
  CHECK(log.trajectory.size() == 33);
  CHECK(log.events.size() == 1);
  CHECK(log.torn_lines == 2);
}

TEST_CASE("a session.json of another format is refused naming the file and the value") {
  ScratchDir scratch;
  write_session(scratch.path(), small_session());
  auto doc = session_json(small_session());
  doc["format"] = "rfbsim-session/2";
  write_text(scratch.path() / "session.json", doc.dump());
  const std::string message = read_error(scratch.path());
  CHECK_THAT(message, Catch::Contains("session.json") && Catch::Contains("rfbsim-session/2"));
}

TEST_CASE("bad trajectory rows are refused with the file, the line number and what is wrong") {
  ScratchDir scratch;
  const std::string header = "tick,time,kind,id,x,y,yaw,vx,vy\n";
  const std::string good = "0,0.000000,avatar,0,1.0,1.0,0,0,0\n";
  struct Case {
    std::string rows;
    std::string expected;
  };
  const Case cases[] = {
      {good + "0,0.0,robot,0,1.0,abc,0,0,0\n", "trajectories.csv:3: column 'y': bad number 'abc'"},
      {good + good + "6,0.1,avatar,0,1.0\n", "trajectories.csv:4: expected 9 columns, got 5"},
      {good + "6,0.1,drone,0,1,1,0,0,0\n", "trajectories.csv:3: unknown kind 'drone'"},
      {good + "6,0.1,person,7,1,1,0,0,0\n", "trajectories.csv:3: person 7 is not among session.json's agents"},
      {good + "6,0.1,avatar,0,nan,1,0,0,0\n", "trajectories.csv:3: column 'x': bad number 'nan'"},
      {"12,0.2,avatar,0,1,1,0,0,0\n" + good, "trajectories.csv:3: tick goes backwards"},
      {good + "-6,0.1,avatar,0,1,1,0,0,0\n", "trajectories.csv:3: column 'tick': bad number '-6'"},
  };
  for (const Case& c : cases) {
    const auto dir = with_file(scratch, "trajectories.csv", header + c.rows);
    CHECK_THAT(read_error(dir), Catch::Contains(c.expected));
  }
  CHECK_THAT(read_error(with_file(scratch, "trajectories.csv", "t,x\n")),
             Catch::Contains("trajectories.csv:1: header"));
  CHECK_THAT(read_error(with_file(scratch, "trajectories.csv", "")),
             Catch::Contains("trajectories.csv:1: no header line"));
}

TEST_CASE("bad event lines are refused with the file, the line number and the key") {
  ScratchDir scratch;
  const std::string start = R"({"tick":0,"time":0.0,"type":"session","event":"start"})" "\n";
  struct Case {
    std::string line;
    std::string expected;
  };
  const Case cases[] = {
      {R"({"tick":1,"time":0.1,"type":"key","keysym":"w","down":true,"client":1})", "events.jsonl:2: key 'keysym'"},
      {R"({"tick":1,"time":0.1,"type":"key","keysym":119,"client":1})", "events.jsonl:2: missing key 'down'"},
      {R"({"tick":1,"time":0.1,"type":"client","event":"connect","client":1,"address":"ab"})",
       "events.jsonl:2: missing key 'websocket'"},
      {R"({"tick":-1,"time":0.1,"type":"timer","event":"started"})", "events.jsonl:2: key 'tick'"},
      {R"({"tick":1,"time":0.1})", "events.jsonl:2: missing key 'type'"},
      {R"([1,2,3])", "events.jsonl:2: not a JSON object"},
      {R"({"tick":1,)", "events.jsonl:2: not JSON"},
      {"", "events.jsonl:2: not JSON"},
  };
  for (const Case& c : cases) {
    const auto dir = with_file(scratch, "events.jsonl", start + c.line + "\n");
    CHECK_THAT(read_error(dir), Catch::Contains(c.expected));
  }
  // Types the reader does not know are kept as they are.
  const auto dir = with_file(scratch, "events.jsonl", start + R"({"tick":1,"time":0.1,"type":"future","x":[1]})" "\n");
  CHECK(read_session(dir).events.at(1).fields.at("x").at(0) == 1);
}

TEST_CASE("bad session.json keys are refused naming the key") {
  ScratchDir scratch;
  const std::pair<std::string, nlohmann::json> cases[] = {
      {"seed", 1234}, {"seed", "12x"}, {"tick_hz", 0}, {"tick_hz", 60.5}, {"uid", nullptr}, {"agents", "none"},
  };
  for (const auto& [key, value] : cases) {
    auto doc = session_json(small_session());
    doc[key] = value;
    const auto dir = with_file(scratch, "session.json", doc.dump());
    CHECK_THAT(read_error(dir), Catch::Contains("session.json: key '" + key + "'"));
  }
  auto doc = session_json(small_session());
  doc.erase("end_reason");
  CHECK_THAT(read_error(with_file(scratch, "session.json", doc.dump())), Catch::Contains("missing key 'end_reason'"));
  doc = session_json(small_session());
  doc["agents"][2]["kind"] = "ghost";
  CHECK_THAT(read_error(with_file(scratch, "session.json", doc.dump())), Catch::Contains("unknown kind 'ghost'"));
  doc = session_json(small_session());
  doc["agents"][2]["kind"] = "avatar";
  CHECK_THAT(read_error(with_file(scratch, "session.json", doc.dump())), Catch::Contains("one avatar"));
  CHECK_THAT(read_error(with_file(scratch, "session.json", "{\"format\":")), Catch::Contains("session.json: not JSON"));
}

TEST_CASE("a missing events.jsonl or trajectories.csv is an error naming it") {
  ScratchDir scratch;
  write_session(scratch.path(), small_session());
  std::filesystem::remove(scratch.path() / "events.jsonl");
  CHECK_THAT(read_error(scratch.path()), Catch::Contains("events.jsonl: missing"));
  write_session(scratch.path(), small_session());
  std::filesystem::remove(scratch.path() / "trajectories.csv");
  CHECK_THAT(read_error(scratch.path()), Catch::Contains("trajectories.csv: missing"));
}

TEST_CASE("session folders are found recursively and sorted, as sim_manager lays them out") {
  ScratchDir scratch;
  write_session(scratch.path() / "sessions" / "2-p002", small_session());
  write_session(scratch.path() / "sessions" / "10-p010", small_session());
  write_session(scratch.path() / "sessions" / "1-p001", small_session());
  std::filesystem::create_directories(scratch.path() / "sessions" / "3-empty");
  write_text(scratch.path() / "index.sqlite", "");
  const auto dirs = rfbsim::sim::find_session_dirs(scratch.path());
  REQUIRE(dirs.size() == 3);
  CHECK(dirs[0] == scratch.path() / "sessions" / "1-p001");
  CHECK(dirs[1] == scratch.path() / "sessions" / "10-p010");
  CHECK(dirs[2] == scratch.path() / "sessions" / "2-p002");
  CHECK(rfbsim::sim::find_session_dirs(scratch.path() / "nowhere").empty());
}

TEST_CASE("mangled session files give SessionLogError or a session the report can measure, never a crash") {
  ScratchDir scratch;
  const std::filesystem::path dir = scratch.path() / "s";
  write_session(dir, small_session());
  const std::string names[] = {"session.json", "trajectories.csv", "events.jsonl"};
  std::string originals[3];
  for (int i = 0; i < 3; ++i) originals[i] = read_text(dir / names[i]);

  std::mt19937 random(12345);  // fixed: the same mangling every run
  int refused = 0, read = 0;
  for (int round = 0; round < 300; ++round) {
    const int which = static_cast<int>(random() % 3);
    std::string bytes = originals[which];
    // Flip, insert or cut a few bytes somewhere.
    for (int edits = 1 + static_cast<int>(random() % 3); edits > 0 && !bytes.empty(); --edits) {
      const std::size_t at = random() % bytes.size();
      switch (random() % 3) {
        case 0: bytes[at] = static_cast<char>(random() % 256); break;
        case 1: bytes.insert(at, 1, "\n,\"{[0-9e."[random() % 10]); break;
        default: bytes.resize(at); break;
      }
    }
    write_text(dir / names[which], bytes);
    try {
      const auto log = read_session(dir);
      const auto samples = rfbsim::report::assemble_samples(log);
      const auto metrics = rfbsim::report::session_metrics(log, samples);
      CHECK_FALSE(rfbsim::report::trajectory_svg(samples, nullptr).empty());
      ++read;
    } catch (const SessionLogError&) {
      ++refused;
    }
    write_text(dir / names[which], originals[which]);
  }
  CHECK(refused + read == 300);
  CHECK(refused > 0);
}
