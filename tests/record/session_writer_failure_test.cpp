// SPDX-License-Identifier: GPL-2.0-or-later
// SessionWriter when the disk fails: a write that fails partway (the injected fault, and a real full tmpfs),
// a disk that stalls until the queue is full. Each time the recording stops, memory stays bounded, the
// session's calls go on without throwing, the folder says why, and what was written reads back.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <future>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "record/session_log.hpp"
#include "record/session_writer.hpp"
#include "file_text.hpp"
#include "scratch_dir.hpp"
#include "skip.hpp"
#include "small_tmpfs.hpp"

using namespace rfbsim::sim;
using nlohmann::json;
using rfbsim::test::file_text;
using rfbsim::test::ScratchDir;
using rfbsim::test::SmallTmpfs;

namespace {

World one_person_world() {
  World world;
  world.avatar.pose = {1.0, 2.0, 0.0};
  Person person;
  person.id = 3;
  person.pose = {4.0, 5.0, 0.0};
  world.people.push_back(person);
  return world;
}

SessionInfo info() {
  SessionInfo info;
  info.uid = "p-full";
  info.scenario = "room";
  return info;
}

// `seconds` of session at 60 ticks a second: a sample every sixth tick, a key event every tick, handed
// over every 30 ticks as sim_rfb's loop does about every half second.
void run_session(SessionWriter& writer, World& world, int seconds) {
  for (int i = 0; i < seconds * 60; ++i) {
    ++world.tick;
    writer.sample(world);
    writer.event(world.tick, "key", {{"keysym", 119}, {"down", i % 2 == 0}, {"client", 1}});
    if (world.tick % 30 == 0) writer.checkpoint();
  }
}

}  // namespace

TEST_CASE("a write that fails partway stops the recording, notes why, and leaves readable files") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "injected";
  World world = one_person_world();
  SessionWriterOptions options;
  options.faults.fail_after_bytes = 3000;  // the header, then a few hundred lines' worth
  SessionWriter writer(dir, info(), world, options);
  CHECK(std::filesystem::exists(dir / "session.json.reserve"));
  run_session(writer, world, 5);
  CHECK_FALSE(writer.flush());
  const std::optional<std::string> failure = writer.failure();
  REQUIRE(failure);
  CHECK_THAT(*failure, Catch::Matches("(trajectories\\.csv|events\\.jsonl): cannot write \\(No space left on device\\)"));
  CHECK(writer.dropped_bytes() > 10000);

  // Everything after the failure is dropped (counted), not kept: the appended files stay as they were.
  const auto size_then = std::filesystem::file_size(dir / "trajectories.csv") + std::filesystem::file_size(dir / "events.jsonl");
  const std::uint64_t dropped_then = writer.dropped_bytes();
  run_session(writer, world, 5);
  CHECK_NOTHROW(writer.outcome("completed", "A1", world.tick));
  writer.flush();
  CHECK(std::filesystem::file_size(dir / "trajectories.csv") + std::filesystem::file_size(dir / "events.jsonl") == size_then);
  CHECK(writer.dropped_bytes() > dropped_then);
  // The reserve was given back for the note.
  CHECK_FALSE(std::filesystem::exists(dir / "session.json.reserve"));
  writer.finish({world.tick, "completed"});

  // The folder reads back: the write cut at the limit left a torn last line, which the reader drops.
  const SessionLog log = read_session(dir);
  CHECK(log.meta.data_incomplete == failure);
  CHECK(log.meta.dropped_bytes == writer.dropped_bytes());
  CHECK(log.meta.outcome == "completed");
  CHECK(log.meta.end_reason == "completed");
  const std::string header = "tick,time,kind,id,x,y,yaw,vx,vy\n";  // written before the writer thread began
  CHECK(std::filesystem::file_size(dir / "trajectories.csv") + std::filesystem::file_size(dir / "events.jsonl") ==
        header.size() + 3000);
  CHECK(log.torn_lines == 1);
  REQUIRE_FALSE(log.trajectory.empty());
  CHECK(log.trajectory.back().tick < 120);  // 3000 bytes hold well under two seconds of this session
  CHECK_FALSE(std::filesystem::exists(dir / "session.json.tmp"));
}

TEST_CASE("a disk that stalls fills the queue up to its bound, then the recording stops instead of growing") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "stalled";
  World world = one_person_world();
  std::promise<void> unstall;
  std::shared_future<void> unstalled = unstall.get_future().share();
  SessionWriterOptions options;
  options.limits.max_queued_bytes = 64 * 1024;
  options.faults.before_step = [unstalled] { unstalled.wait(); };
  SessionWriter writer(dir, info(), world, options);
  // The session goes on while the disk takes nothing: about 7 KiB a second of lines here.
  run_session(writer, world, 20);
  const std::optional<std::string> failure = writer.failure();
  REQUIRE(failure);
  CHECK(*failure == "the disk fell behind: more than 64 KiB waiting to be written");
  CHECK(writer.dropped_bytes() > 0);
  unstall.set_value();
  writer.finish({world.tick, "signal"});

  const SessionLog log = read_session(dir);
  CHECK(log.meta.data_incomplete == failure);
  CHECK(log.meta.end_reason == "signal");
  // What was queued before the bound was still written, as whole lines, and nothing after it.
  const auto written = std::filesystem::file_size(dir / "trajectories.csv") + std::filesystem::file_size(dir / "events.jsonl");
  CHECK(written > 48 * 1024);
  CHECK(written <= 72 * 1024);  // the bound, the header and the one step the stalled thread held
  CHECK(log.torn_lines == 0);
  REQUIRE_FALSE(log.trajectory.empty());
  CHECK(log.trajectory.back().tick < 20 * 60);
}

TEST_CASE("a real full disk (a 64 KiB tmpfs) stops the recording with the kernel's reason, noted in session.json") {
  ScratchDir scratch;
  const auto mount_point = scratch.path() / "mnt";
  std::filesystem::create_directories(mount_point);
  SmallTmpfs tmpfs(mount_point, 64 * 1024);
  if (!tmpfs.mounted()) RFBSIM_SKIP(tmpfs.why_not());
  const auto dir = mount_point / "session";
  World world = one_person_world();
  SessionWriter writer(dir, info(), world);
  run_session(writer, world, 30);  // about 200 KiB of lines: far more than fits
  CHECK_FALSE(writer.flush());
  const std::optional<std::string> failure = writer.failure();
  REQUIRE(failure);
  CHECK_THAT(*failure, Catch::Contains("No space left on device"));
  writer.finish({world.tick, "signal"});

  // The disk is full, yet session.json carries the reason and the end: the reserved space made room.
  const SessionLog log = read_session(dir);
  CHECK(log.meta.data_incomplete == failure);
  CHECK(log.meta.end_reason == "signal");
  CHECK(log.meta.dropped_bytes > 0);
  CHECK_FALSE(log.trajectory.empty());
  CHECK(log.torn_lines <= 2);
}

TEST_CASE("a session that ends well gives the reserved space back and has no data_incomplete key") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "clean";
  World world = one_person_world();
  {
    SessionWriter writer(dir, info(), world);
    run_session(writer, world, 1);
    CHECK(writer.flush());
    CHECK_FALSE(writer.failure());
    writer.finish({world.tick, "completed"});
  }
  CHECK_FALSE(std::filesystem::exists(dir / "session.json.reserve"));
  CHECK_FALSE(json::parse(file_text(dir / "session.json")).contains("data_incomplete"));
  const SessionLog log = read_session(dir);
  CHECK_FALSE(log.meta.data_incomplete);
  CHECK(log.trajectory.size() == 2 * 10);  // ticks 6..60 for the avatar and the person
  CHECK(log.events.size() == 60);
}
