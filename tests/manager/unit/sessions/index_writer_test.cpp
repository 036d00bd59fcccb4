// SPDX-License-Identifier: GPL-2.0-or-later
// IndexWriter: writes in order on its own thread, reports each, and leaves nothing unwritten at destruction.
#include "sessions/index_writer.hpp"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "scratch_dir.hpp"
#include "sessions/session_index.hpp"

using rfbsim::manager::IndexWriter;
using rfbsim::manager::Session;
using rfbsim::manager::SessionIndex;
using rfbsim::manager::SessionState;

namespace {
Session make(std::int64_t id, const std::string& uid) {
  Session s;
  s.id = id;
  s.uid = uid;
  s.token = std::string(30, '0') + std::to_string(10 + id);
  s.scenario = "lab";
  s.params_json = "{}";
  s.host_id = "h";
  return s;
}
}  // namespace

TEST_CASE("the writer's inserts and updates land in order, each reported, all before it is gone") {
  rfbsim::test::ScratchDir dir;
  const std::string path = dir.path("sessions.db");
  SessionIndex reader(path);
  std::mutex mutex;
  std::vector<std::string> reports;
  {
    IndexWriter writer(path);
    Session session = make(5, "p01");
    session.data_path = dir.path("5-p01");
    std::filesystem::create_directories(session.data_path);
    writer.insert(session, [&](const std::string& error) {
      std::lock_guard<std::mutex> lock(mutex);
      reports.push_back("insert:" + error);
    });
    for (const SessionState state : {SessionState::kRunning, SessionState::kEnding, SessionState::kIdle}) {
      session.state = state;
      writer.update(session, [&](const std::string& error) {
        std::lock_guard<std::mutex> lock(mutex);
        reports.push_back("update:" + error);
      });
    }
    writer.drain();
    CHECK(reader.find_by_token(session.token)->state == SessionState::kIdle);
    // manager.json follows the row.
    std::ifstream record(session.data_path + "/manager.json");
    std::stringstream text;
    text << record.rdbuf();
    CHECK(text.str().find("\"state\":\"idle\"") != std::string::npos);
    // An update of a row that does not exist yet writes the whole row: its insert had been refused (a full disk),
    // and the retry of the newest version records the session.
    writer.update(make(9, "ghost"), [&](const std::string& error) {
      std::lock_guard<std::mutex> lock(mutex);
      reports.push_back(error.empty() ? "ghost:ok" : "ghost:error");
    });
    writer.insert(make(6, "p02"), nullptr);
  }  // destruction writes what is queued
  CHECK(reports == std::vector<std::string>{"insert:", "update:", "update:", "update:", "ghost:ok"});
  CHECK(reader.find_by_token(make(9, "ghost").token));
  CHECK(reader.find_by_token(make(6, "p02").token));
}
