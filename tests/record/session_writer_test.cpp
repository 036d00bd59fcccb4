// SPDX-License-Identifier: GPL-2.0-or-later
// SessionWriter on a tiny world: what is on disk before and after a flush, session.json replaced whole,
// the end keys, event lines, and keyed address hashes.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "record/digest.hpp"
#include "record/session_writer.hpp"
#include "file_text.hpp"
#include "scratch_dir.hpp"

using namespace rfbsim::sim;
using rfbsim::test::file_text;
using rfbsim::test::ScratchDir;
using nlohmann::json;

namespace {

World tiny_world() {
  World world;
  world.avatar.pose = {1.0, 2.0, 0.5};
  world.avatar.speed = 1.0;
  Person person;
  person.id = 7;
  person.pose = {3.0, 4.0, -0.25};
  person.velocity = Eigen::Vector2d(0.5, -0.125);
  world.people.push_back(person);
  return world;
}

SessionInfo tiny_info() {
  SessionInfo info;
  info.uid = "p-1";
  info.scenario = "room";
  info.seed = 18446744073709551615ULL;
  info.parameters = {{"crowd", "1"}};
  return info;
}

}  // namespace

TEST_CASE("rows and events reach the files at a flush, whole lines only, every sixth tick sampled") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "flush";
  World world = tiny_world();
  SessionWriter writer(dir, tiny_info(), world, std::chrono::hours(1));
  CHECK(file_text(dir / "trajectories.csv") == "tick,time,kind,id,x,y,yaw,vx,vy\n");
  for (int i = 0; i <= 12; ++i) {
    world.tick = static_cast<std::uint64_t>(i);
    writer.sample(world);
  }
  writer.event(3, "key", {{"keysym", 119}, {"down", true}, {"client", 1}});
  writer.flush_if_due();  // an hour has not passed: nothing written yet
  CHECK(file_text(dir / "trajectories.csv") == "tick,time,kind,id,x,y,yaw,vx,vy\n");
  CHECK(file_text(dir / "events.jsonl").empty());
  writer.flush();
  const std::string rows = file_text(dir / "trajectories.csv");
  CHECK(rows ==
        "tick,time,kind,id,x,y,yaw,vx,vy\n"
        "0,0.000000,avatar,0,1.000000,2.000000,0.500000,0.877583,0.479426\n"
        "0,0.000000,person,7,3.000000,4.000000,-0.250000,0.500000,-0.125000\n"
        "6,0.100000,avatar,0,1.000000,2.000000,0.500000,0.877583,0.479426\n"
        "6,0.100000,person,7,3.000000,4.000000,-0.250000,0.500000,-0.125000\n"
        "12,0.200000,avatar,0,1.000000,2.000000,0.500000,0.877583,0.479426\n"
        "12,0.200000,person,7,3.000000,4.000000,-0.250000,0.500000,-0.125000\n");
  CHECK(file_text(dir / "events.jsonl") == "{\"tick\":3,\"time\":0.05,\"type\":\"key\",\"keysym\":119,\"down\":true,\"client\":1}\n");
}

TEST_CASE("the flush interval hands lines to the disk without an explicit flush") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "interval";
  World world = tiny_world();
  SessionWriter writer(dir, tiny_info(), world, std::chrono::milliseconds(1));
  writer.event(0, "session", {{"event", "start"}});
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  writer.flush_if_due();
  // The writer thread writes it soon; wait for it, however slow the machine.
  const std::string expected = "{\"tick\":0,\"time\":0.0,\"type\":\"session\",\"event\":\"start\"}\n";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (file_text(dir / "events.jsonl") != expected && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  CHECK(file_text(dir / "events.jsonl") == expected);
}

TEST_CASE("session.json is complete from the start and gains the outcome, tasks and end") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "session";
  World world = tiny_world();
  SessionInfo info = tiny_info();
  info.codes = std::make_pair(std::string("A1"), std::string("B2"));
  info.tasks = {{"reach", "Walk there"}};
  info.time_limit = 240.0;
  SessionWriter writer(dir, info, world);
  json session = json::parse(file_text(dir / "session.json"));
  CHECK(session["seed"] == "18446744073709551615");
  CHECK(session["parameters"] == json{{"crowd", "1"}});
  CHECK(session["agents"] == json::parse(R"([{"kind":"avatar","id":0,"radius":0.25},{"kind":"person","id":7,"radius":0.25}])"));
  CHECK(session["outcome"].is_null());
  CHECK(session["ended_at"].is_null());
  CHECK(session["codes"] == json{{"success", "A1"}, {"timeout", "B2"}});
  writer.task_done("reach", 120);
  writer.outcome("completed", "A1", 120);
  writer.flush();  // the writer thread has written what was handed over
  session = json::parse(file_text(dir / "session.json"));
  CHECK(session["tasks_done"] == json::parse(R"([{"type":"reach","tick":120,"time":2.0}])"));
  CHECK(session["completion"] == json::parse(R"({"code":"A1","tick":120,"time":2.0})"));
  CHECK(session["outcome"] == "completed");
  writer.finish({720, "completed"});
  session = json::parse(file_text(dir / "session.json"));
  CHECK(session["end_tick"] == 720);
  CHECK(session["end_reason"] == "completed");
  CHECK(session["ended_at"].is_string());
  CHECK_FALSE(std::filesystem::exists(dir / "session.json.tmp"));
}

TEST_CASE("text from outside that is not UTF-8 is written replaced, never thrown") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "utf8";
  World world = tiny_world();
  SessionWriter writer(dir, tiny_info(), world);
  writer.event(1, "robot", {{"state", "failed"}, {"detail", std::string("bad \xff byte")}});
  writer.flush();
  const json event = json::parse(file_text(dir / "events.jsonl"));
  CHECK(event["detail"].get<std::string>().find("bad ") == 0);
}

TEST_CASE("a trajectory rate that does not divide the tick rate is refused") {
  SessionInfo info = tiny_info();
  info.trajectory_hz = 7;
  ScratchDir scratch;
  CHECK_THROWS_WITH(SessionWriter(scratch.path() / "rate", info, tiny_world()), Catch::Contains("7 Hz"));
}

TEST_CASE("addresses hash alike under one key, differently under another, and never show") {
  const std::string a = hash_address("key one", "203.0.113.5");
  CHECK(a.size() == 16);
  CHECK(a == hash_address("key one", "203.0.113.5"));
  CHECK(a != hash_address("key two", "203.0.113.5"));
  CHECK(a != hash_address("key one", "203.0.113.6"));
  CHECK(a.find("203") == std::string::npos);
  ::setenv("RFBSIM_ADDRESS_KEY", "study key", 1);
  CHECK(address_hash_key() == "study key");
  ::unsetenv("RFBSIM_ADDRESS_KEY");
  const std::string drawn = address_hash_key();
  CHECK(drawn.size() == 32);
  CHECK(drawn != address_hash_key());
}

TEST_CASE("file digests are SHA-256") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "digest";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "abc") << "abc";
  CHECK(sha256_file(dir / "abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK_THROWS_WITH(sha256_file(dir / "missing"), Catch::Contains("missing"));
}

TEST_CASE("a folder that already holds a session is not recorded into again") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "twice";
  { SessionWriter first(dir, tiny_info(), tiny_world()); }
  CHECK_THROWS_WITH(SessionWriter(dir, tiny_info(), tiny_world()), Catch::Contains("already holds a session"));
}

TEST_CASE("a full disk stops the recording, not the session, and a first write that fails is an error") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "full";
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink("/dev/full", dir / "events.jsonl");  // every write: ENOSPC
  World world = tiny_world();
  SessionWriter writer(dir, tiny_info(), world);
  writer.event(1, "key", {{"keysym", 119}, {"down", true}, {"client", 1}});
  CHECK_FALSE(writer.flush());
  CHECK(writer.failure() == "events.jsonl: cannot write (No space left on device)");
  CHECK_NOTHROW(writer.outcome("completed", "A1", 2));  // noted, not thrown
  writer.flush();
  const json session = json::parse(file_text(dir / "session.json"));
  CHECK(session["outcome"] == "completed");
  CHECK(session["data_incomplete"]["reason"] == "events.jsonl: cannot write (No space left on device)");
  CHECK(session["data_incomplete"]["dropped_bytes"].get<std::uint64_t>() > 0);

  const auto header_dir = scratch.path() / "full_header";
  std::filesystem::create_directories(header_dir);
  std::filesystem::create_symlink("/dev/full", header_dir / "trajectories.csv");
  CHECK_THROWS_WITH(SessionWriter(header_dir, tiny_info(), world), Catch::Contains("trajectories.csv"));
}
