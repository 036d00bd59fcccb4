// SPDX-License-Identifier: GPL-2.0-or-later
// Whole sessions through StudySession, as sim_rfb runs them but with a scripted participant: the tutorial
// completed with keys, the lab timed out, and the session data they leave, parsed and compared with the world.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/session_setup.hpp"
#include "app/study_session.hpp"
#include "record/session_log.hpp"
#include "scratch_dir.hpp"

using namespace rfbsim::sim;
using rfbsim::test::ScratchDir;
using nlohmann::json;

namespace {

constexpr std::uint32_t kKeyW = 'w', kKeyA = 'a', kKeyUp = 0xff52;

std::vector<std::string> lines_of(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

std::string row_text(std::uint64_t tick, const char* kind, int id, const Pose2& pose, double vx, double vy) {
  const auto p = [](double v) { return std::abs(v) < 5e-7 ? 0.0 : v; };
  char text[256];
  std::snprintf(text, sizeof text, "%llu,%.6f,%s,%d,%.6f,%.6f,%.6f,%.6f,%.6f", static_cast<unsigned long long>(tick),
                static_cast<double>(tick) / 60.0, kind, id, p(pose.x), p(pose.y), p(pose.yaw), p(vx), p(vy));
  return text;
}

SessionInfo info_for(const PreparedSession& prepared, const std::string& uid) {
  SessionInfo info = prepared.info;
  info.uid = uid;
  info.codes = std::make_pair(std::string("OK-1"), std::string("LATE-2"));
  return info;
}

}  // namespace

TEST_CASE("a scripted participant completes the tutorial, and the session data tell the same story") {
  SessionSetup setup;
  setup.scenario = "tutorial";
  setup.parameters = {{"avatar_goal", "8.4,5.4"}};  // 1 m back toward the start, reached after the turn
  PreparedSession prepared = prepare_session(setup);
  Simulation& simulation = *prepared.simulation;
  ScratchDir scratch;
  const auto dir = scratch.path() / "tutorial";
  std::map<std::uint64_t, std::string> expected_rows;  // the avatar's row at every sample tick, from the world
  {
    SessionWriter writer(dir, info_for(prepared, "p-tutorial"), simulation.world());
    StudySession study(simulation, prepared.task, {"OK-1", "LATE-2"}, &writer);
    study.client_connected(1, "0123456789abcdef", true);
    // The participant: W until the walk is done, A until the turn is, Up until the camera step is, then W.
    const std::uint32_t keys[] = {kKeyW, kKeyA, kKeyUp, kKeyW};
    int held_for = -1;
    while (!study.over() && simulation.world().tick < 60 * 120) {
      const int step = study.task().status().step;
      if (study.outcome() == TaskOutcome::None && step != held_for) {
        if (held_for >= 0) study.key(keys[held_for], false, 1);
        study.key(keys[step], true, 1);
        held_for = step;
      } else if (study.outcome() != TaskOutcome::None && held_for >= 0) {
        study.key(keys[held_for], false, 1);
        held_for = -1;
      }
      study.step();
      const World& w = simulation.world();
      if (w.tick % 6 == 0) {
        expected_rows[w.tick] = row_text(w.tick, "avatar", 0, w.avatar.pose, std::cos(w.avatar.pose.yaw) * w.avatar.speed,
                                         std::sin(w.avatar.pose.yaw) * w.avatar.speed);
      }
    }
    REQUIRE(study.outcome() == TaskOutcome::Completed);
    CHECK(study.outcome_code() == "OK-1");
    CHECK(study.text().centre == std::vector<std::string>{"Task complete. Thank you!", "Your completion code:", "OK-1"});
    study.finish("completed");
  }
  const std::uint64_t end_tick = simulation.world().tick;

  const json session = read_json(dir / "session.json");
  CHECK(session["format"] == "rfbsim-session/1");
  CHECK(session["uid"] == "p-tutorial");
  CHECK(session["scenario"] == "tutorial");
  CHECK(session["parameters"]["avatar_goal"] == "8.4,5.4");
  CHECK(session["outcome"] == "completed");
  CHECK(session["completion"]["code"] == "OK-1");
  CHECK(session["end_reason"] == "completed");
  CHECK(session["end_tick"] == end_tick);
  CHECK(session["tasks_done"].size() == 4);
  CHECK(session["tasks_done"][3]["type"] == "reach");
  CHECK(session["versions"]["scenario_sha256"].get<std::string>().size() == 64);
  // The outcome came, then the grace period of the tutorial (10 s) ran out.
  const std::uint64_t outcome_tick = session["completion"]["tick"];
  CHECK(end_tick == outcome_tick + 600);

  // Every event line parses; keys are recorded at the ticks they were applied; the story is in order.
  std::vector<std::string> story;
  std::uint64_t last_tick = 0;
  int key_downs = 0;
  for (const std::string& line : lines_of(dir / "events.jsonl")) {
    const json event = json::parse(line);
    CHECK(event["tick"].get<std::uint64_t>() >= last_tick);
    last_tick = event["tick"];
    const std::string type = event["type"];
    if (type == "key" && event["down"] == true) ++key_downs;
    if (type == "task" || type == "outcome" || type == "timer" || type == "session" || type == "client") {
      story.push_back(type + ":" + (event.contains("event") ? event["event"].get<std::string>() : event["outcome"].get<std::string>()));
    }
  }
  CHECK(key_downs == 4);
  const std::vector<std::string> expected_story = {
      "session:start", "client:connect", "timer:started", "task:started", "task:done", "task:started", "task:done",
      "task:started", "task:done", "task:started", "task:done", "outcome:completed", "session:end"};
  CHECK(story == expected_story);

  // The avatar's rows are the world's poses at every sample tick, to the last digit written.
  std::size_t matched = 0;
  const auto rows = lines_of(dir / "trajectories.csv");
  REQUIRE(rows.front() == "tick,time,kind,id,x,y,yaw,vx,vy");
  for (const std::string& row : rows) {
    if (row.find(",avatar,") == std::string::npos) continue;
    const std::uint64_t tick = std::stoull(row.substr(0, row.find(',')));
    if (tick == 0) continue;
    REQUIRE(expected_rows.count(tick) == 1);
    CHECK(row == expected_rows[tick]);
    ++matched;
  }
  CHECK(matched == expected_rows.size());
  CHECK(matched == end_tick / 6);
}

namespace {

// Records into `dir` a lab session with a 3 s limit (and `setup`'s other settings) whose participant connects
// at tick `connect_tick` and does nothing: it times out 180 ticks later. The session runs to its own end.
void record_idle_lab_timeout(SessionSetup setup, const std::filesystem::path& dir, int connect_tick) {
  setup.scenario = "lab";
  setup.time_limit = 3.0;
  PreparedSession prepared = prepare_session(setup);
  Simulation& simulation = *prepared.simulation;
  SessionWriter writer(dir, info_for(prepared, "p-idle"), simulation.world());
  StudySession study(simulation, prepared.task, {"OK-1", "LATE-2"}, &writer);
  for (int i = 0; i < connect_tick; ++i) study.step();
  study.client_connected(1, "0123456789abcdef", true);  // the clock starts here
  while (!study.over() && simulation.world().tick < 60 * 60) study.step();
  REQUIRE(study.outcome() == TaskOutcome::Timeout);
  CHECK(*study.task().outcome_tick() == static_cast<std::uint64_t>(connect_tick + 180));
  study.finish("timeout");
}

}  // namespace

TEST_CASE("a participant who does nothing in the lab times out at the limit and gets the timeout code") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "lab_timeout";
  record_idle_lab_timeout({}, dir, 30);
  const json session = read_json(dir / "session.json");
  CHECK(session["outcome"] == "timeout");
  CHECK(session["completion"]["code"] == "LATE-2");
  CHECK(session["completion"]["tick"] == 210);
  CHECK(session["time_limit_s"] == 3.0);
  CHECK(session["end_grace_s"] == 15.0);  // the lab's
  CHECK(session["end_tick"] == 210 + 15 * 60);
  // Every agent is in every sample: avatar, robot and the lab's one pedestrian.
  const auto rows = lines_of(dir / "trajectories.csv");
  CHECK(rows.size() == 1 + 3 * ((210 + 900) / 6 + 1));
  const json agents = session["agents"];
  REQUIRE(agents.size() == 3);
  CHECK(agents[1]["kind"] == "robot");
  CHECK(agents[1]["radius"] == 0.16);
}

TEST_CASE("an end grace given instead of the scenario's ends the session that much after the outcome, recorded") {
  SessionSetup setup;
  setup.end_grace = 2.0;
  ScratchDir scratch;
  const auto dir = scratch.path() / "lab_short_grace";
  record_idle_lab_timeout(setup, dir, 0);
  const json session = read_json(dir / "session.json");
  CHECK(session["end_grace_s"] == 2.0);
  CHECK(session["end_tick"] == 180 + 2 * 60);
  // Read back as sim_replay reads it, which rebuilds the session with the same grace.
  CHECK(rfbsim::sim::read_session(dir).meta.end_grace_s == 2.0);
}

TEST_CASE("a researcher watching before the participant comes does not start the participant's clock") {
  SessionSetup setup;
  setup.scenario = "lab";
  setup.time_limit = 3.0;
  PreparedSession prepared = prepare_session(setup);
  Simulation& simulation = *prepared.simulation;
  ScratchDir scratch;
  const auto dir = scratch.path() / "lab_watched";
  {
    SessionWriter writer(dir, info_for(prepared, "p-watched"), simulation.world());
    StudySession study(simulation, prepared.task, {"OK-1", "LATE-2"}, &writer);
    study.client_connected(1, "aaaaaaaaaaaaaaaa", false, ViewerRole::kWatcher);  // at tick 0
    for (int i = 0; i < 300; ++i) study.step();
    // Five seconds watched, longer than the whole limit: no clock, no step, no outcome.
    CHECK_FALSE(study.task().outcome_tick());
    CHECK(study.outcome() == TaskOutcome::None);
    study.client_disconnected(1, "aaaaaaaaaaaaaaaa", false);
    study.client_connected(2, "0123456789abcdef", false);  // the participant, at tick 300
    study.client_connected(3, "aaaaaaaaaaaaaaaa", false, ViewerRole::kWatcher);  // a second look changes nothing
    while (!study.over() && simulation.world().tick < 60 * 60) study.step();
    REQUIRE(study.outcome() == TaskOutcome::Timeout);
    CHECK(*study.task().outcome_tick() == 300 + 180);
    study.finish("timeout");
  }
  // The record says who came when, and the clock started with the participant only.
  std::vector<std::string> story;
  for (const std::string& line : lines_of(dir / "events.jsonl")) {
    const json event = json::parse(line);
    if (event["type"] == "client") {
      story.push_back("client:" + event["event"].get<std::string>() + ":" + std::to_string(event["client"].get<int>()) +
                      ":" + event.value("role", std::string("participant")) + "@" + std::to_string(event["tick"].get<int>()));
    } else if (event["type"] == "timer") {
      story.push_back("timer@" + std::to_string(event["tick"].get<int>()));
    }
  }
  const std::vector<std::string> expected = {"client:connect:1:watcher@0", "client:disconnect:1:participant@300",
                                             "client:connect:2:participant@300", "timer@300",
                                             "client:connect:3:watcher@300"};
  CHECK(story == expected);
  CHECK(viewer_role_name(ViewerRole::kWatcher) == std::string("watcher"));
  CHECK(viewer_role_name(ViewerRole::kParticipant) == std::string("participant"));
}

TEST_CASE("a session only ever watched keeps its clock stopped") {
  SessionSetup setup;
  setup.scenario = "lab";
  setup.time_limit = 1.0;
  PreparedSession prepared = prepare_session(setup);
  StudySession study(*prepared.simulation, prepared.task, {}, nullptr);
  study.client_connected(1, "aaaaaaaaaaaaaaaa", false, ViewerRole::kWatcher);
  for (int i = 0; i < 180; ++i) study.step();
  CHECK(study.outcome() == TaskOutcome::None);
  CHECK_FALSE(study.over());
}
