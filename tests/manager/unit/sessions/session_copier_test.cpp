// SPDX-License-Identifier: GPL-2.0-or-later
// The copier runs real commands on its thread against a real index: a copy that works is 'done' after one try,
// a failure records the exit and the command's last words, a try past its timeout is stopped, a missing program
// or folder is named, and a copier stopped mid-try leaves the copy 'pending' without counting the try. The
// index starts a copy only from none, and lists the pending ones.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "eventually.hpp"
#include "scratch_dir.hpp"
#include "sessions/session_copier.hpp"
#include "sessions/session_index.hpp"

using rfbsim::manager::CopierSettings;
using rfbsim::manager::copy_job_for;
using rfbsim::manager::CopyOutcome;
using rfbsim::manager::Session;
using rfbsim::manager::SessionCopier;
using rfbsim::manager::SessionIndex;
using rfbsim::manager::SessionState;
using rfbsim::test::eventually;
using rfbsim::test::ScratchDir;
using namespace std::chrono_literals;

namespace {

// An ended session of host h1 whose folder (with one file in it) exists under `dir`.
Session ended_session(const ScratchDir& dir, SessionIndex& index, std::int64_t id) {
  Session s;
  s.id = id;
  s.uid = "p-" + std::to_string(id);
  s.token = std::string(31, 'a') + std::to_string(id % 10);
  s.scenario = "lab";
  s.params_json = "{}";
  s.host_id = "h1";
  s.state = SessionState::kFinished;
  s.data_path = (dir.path() / "sessions" / (std::to_string(id) + "-" + s.uid)).string();
  s.created = std::chrono::system_clock::now();
  std::filesystem::create_directories(s.data_path);
  std::ofstream(s.data_path + "/events.jsonl") << "{\"t\":1}\n";
  index.insert(s);
  return s;
}

CopierSettings settings_for(const ScratchDir& dir, std::vector<std::string> command) {
  CopierSettings settings;
  settings.command = std::move(command);
  settings.retries = 0;
  settings.timeout = 30s;
  settings.kill_grace = 1s;
  settings.index_path = dir.path("sessions.db");
  settings.log_dir = dir.path("copy-logs");
  return settings;
}

// The outcomes a copier reports, collected from its thread.
struct Outcomes {
  std::mutex mutex;
  std::vector<CopyOutcome> list;
  SessionCopier::Report report() {
    return [this](const CopyOutcome& outcome) {
      std::lock_guard<std::mutex> lock(mutex);
      list.push_back(outcome);
    };
  }
};

}  // namespace

TEST_CASE("a copy that works is done after one try, with the placeholders filled in") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  const Session s = ended_session(dir, index, 3);
  std::filesystem::create_directories(dir.path() / "store" / "h1");
  Outcomes outcomes;
  {
    SessionCopier copier(
        settings_for(dir, {"cp", "-r", "{folder}", dir.path("store") + "/{host}/{folder_name}-{uid}-{session_id}"}),
        outcomes.report());
    copier.enqueue(copy_job_for(s));
    copier.enqueue(copy_job_for(s));  // once is enough
    copier.drain();
  }
  REQUIRE(outcomes.list.size() == 1);
  CHECK(outcomes.list[0].state == "done");
  CHECK(outcomes.list[0].attempts == 1);
  CHECK(dir.read("store/h1/3-p-3-p-3-3/events.jsonl") == "{\"t\":1}\n");
  const auto row = index.find_by_token(s.token);
  REQUIRE(row);
  CHECK(row->copy_state == "done");
  CHECK(row->copy_attempts == 1);
  CHECK(row->copy_error == "");
  // The command's log lies beside the session folders, not in the folder it copied.
  CHECK(dir.read("copy-logs/3-p-3.log").find("--- try 1 at ") == 0);
  CHECK_FALSE(std::filesystem::exists(s.data_path + "/copy.log"));
  CHECK((std::filesystem::status(dir.path("copy-logs")).permissions() & std::filesystem::perms::group_all) ==
        std::filesystem::perms::none);
}

TEST_CASE("a failed copy records its exit and the command's last line, and fails once its tries are spent") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  const Session s = ended_session(dir, index, 4);
  Outcomes outcomes;
  {
    SessionCopier copier(settings_for(dir, {"/bin/sh", "-c", "echo first; echo \"no route to $0\" >&2; exit 23",
                                            "store-{host}"}),
                         outcomes.report());
    copier.enqueue(copy_job_for(s));
    copier.drain();
  }
  REQUIRE(outcomes.list.size() == 1);
  CHECK(outcomes.list[0].state == "failed");
  const auto row = index.find_by_token(s.token);
  REQUIRE(row);
  CHECK(row->copy_state == "failed");
  CHECK(row->copy_attempts == 1);
  CHECK(row->copy_error == "exit 23: no route to store-h1");
}

TEST_CASE("a try past its timeout is stopped with SIGTERM, and so is what it started") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  const Session s = ended_session(dir, index, 5);
  CopierSettings settings = settings_for(dir, {"/bin/sh", "-c", "sleep 60 & echo $! > " + dir.path("child") + "; wait"});
  settings.timeout = 1s;
  {
    SessionCopier copier(settings);
    copier.enqueue(copy_job_for(s));
    copier.drain();
  }
  const auto row = index.find_by_token(s.token);
  REQUIRE(row);
  CHECK(row->copy_state == "failed");
  CHECK(row->copy_error == "timed out after 1 s (signal 15)");
  const pid_t child = static_cast<pid_t>(std::stol(dir.read("child")));
  CHECK(eventually([&] { return ::kill(child, 0) != 0; }, 5s));  // the group went with it
}

TEST_CASE("a program that is not there, or a folder that is gone, is named") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  const Session a = ended_session(dir, index, 6);
  Session b = ended_session(dir, index, 7);
  std::filesystem::remove_all(b.data_path);
  {
    SessionCopier copier(settings_for(dir, {"no-such-copy-program-xyz", "{folder}"}));
    copier.enqueue(copy_job_for(a));
    copier.enqueue(copy_job_for(b));
    copier.drain();
  }
  CHECK(index.find_by_token(a.token)->copy_error == "cannot run no-such-copy-program-xyz: not found in PATH");
  CHECK(index.find_by_token(b.token)->copy_state == "failed");
  CHECK(index.find_by_token(b.token)->copy_error == "the session folder " + b.data_path + " is not there");
  CHECK(index.find_by_token(b.token)->copy_attempts == 1);
}

TEST_CASE("a copier stopped mid-try stops the command and leaves the copy pending, its try not counted") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  Session s = ended_session(dir, index, 8);
  s.copy_state = "pending";
  index.update(s);
  {
    SessionCopier copier(settings_for(dir, {"/bin/sh", "-c", "echo $$ > " + dir.path("pid") + "; exec sleep 60"}));
    copier.enqueue(copy_job_for(s));
    REQUIRE(eventually([&] { return !dir.read("pid").empty(); }, 10s));
    const pid_t pid = static_cast<pid_t>(std::stol(dir.read("pid")));
    CHECK(copier.may_own(pid));
    CHECK_FALSE(copier.may_own(::getpid()));
  }
  const auto row = index.find_by_token(s.token);
  REQUIRE(row);
  CHECK(row->copy_state == "pending");
  CHECK(row->copy_attempts == 0);
  CHECK(index.pending_copies("h1").size() == 1);
  CHECK(index.pending_copies("h2").empty());
}

TEST_CASE("the index starts a copy only from none: later session updates never undo the copier's record") {
  ScratchDir dir("rfbsim_copier");
  SessionIndex index(dir.path("sessions.db"));
  Session s = ended_session(dir, index, 9);
  index.update(s);
  CHECK(index.find_by_token(s.token)->copy_state == "");
  s.copy_state = "pending";
  index.update(s);
  CHECK(index.find_by_token(s.token)->copy_state == "pending");
  index.set_copy_status(s.id, "done", 2, "");
  index.update(s);  // an older version of the session, still saying pending
  const auto row = index.find_by_token(s.token);
  CHECK(row->copy_state == "done");
  CHECK(row->copy_attempts == 2);
  CHECK_THROWS_WITH(index.set_copy_status(99, "done", 1, ""),
                    "session index: no session 99 to record a copy for");
}

TEST_CASE("a program name is looked up in PATH, a path is taken as it is") {
  ScratchDir dir("rfbsim_copier");
  const std::string tool = dir.write("copy-tool", "#!/bin/sh\n");
  ::chmod(tool.c_str(), 0700);
  dir.write("not-executable", "");
  std::filesystem::create_directories(dir.path() / "bin" / "copy-dir");
  const std::string path = dir.path("bin") + "::" + dir.path().string();
  CHECK(rfbsim::manager::find_program("copy-tool", path) == tool);
  CHECK(rfbsim::manager::find_program("not-executable", path) == "");
  CHECK(rfbsim::manager::find_program("copy-dir", path) == "");
  CHECK(rfbsim::manager::find_program("./relative/x", path) == "./relative/x");
  CHECK_FALSE(rfbsim::manager::find_program("sh", "").empty());  // the usual PATH without one
}
