// SPDX-License-Identifier: GPL-2.0-or-later
// The after-session copy through a real sim_manager with real sim_rfb sessions: an ended session's folder is
// copied to a store (the same files), a command that fails twice is tried again until it works, one that always
// fails ends 'failed' with its words recorded while the manager carries on (and its reaper and the copier's never
// take each other's children), and a copy cut short by a killed manager is done by the next one.
#include <catch2/catch.hpp>
#include <sqlite3.h>
#include <sys/stat.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "file_text.hpp"
#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
namespace fs = std::filesystem;

namespace {

constexpr const char* kHost = "copy-host";
// sim_rfb refuses a goal off the map before it listens and exits with 2: a session that ends at once.
constexpr const char* kFailingStart = "scenario=lab&robot_goal=500,500,0";

// A session row's copy columns.
struct CopyColumns {
  std::string state;
  int attempts = -1;
  std::string error;
};

// The copy columns of `token`'s row, read through our own connection; state "?" when there is no row.
CopyColumns copy_columns(const fs::path& data_dir, const std::string& token) {
  CopyColumns out{"?", -1, ""};
  sqlite3* db = nullptr;
  if (sqlite3_open_v2((data_dir / "sessions.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    return out;
  }
  sqlite3_busy_timeout(db, 2000);
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, "SELECT copy_state, copy_attempts, copy_error FROM sessions WHERE token = ?", -1, &stmt,
                         nullptr) == SQLITE_OK) {
    sqlite3_bind_text(stmt, 1, token.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(stmt) == SQLITE_ROW) {
      out.state = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
      out.attempts = sqlite3_column_int(stmt, 1);
      out.error = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 2));
    }
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return out;
}

// Waits until `token`'s copy is in `state` ("done", "failed"); its columns then, or as they last were.
CopyColumns wait_for_copy(const fs::path& data_dir, const std::string& token, const std::string& state,
                          std::chrono::milliseconds timeout) {
  CopyColumns last;
  rfbsim::test::eventually(
      [&] {
        last = copy_columns(data_dir, token);
        return last.state == state;
      },
      timeout, 50ms);
  return last;
}

// Every regular file under `root` by its path relative to it, with its content.
std::map<std::string, std::string> tree(const fs::path& root) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (!it->is_regular_file()) continue;
    std::ifstream in(it->path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    files[fs::relative(it->path(), root).string()] = text.str();
  }
  return files;
}

// Writes an executable shell script.
std::string write_script(const fs::path& path, const std::string& body) {
  std::ofstream(path) << "#!/bin/sh\n" << body;
  fs::permissions(path, fs::perms::owner_all);
  return path.string();
}

// The flags of a manager whose sessions are copied with `command`.
std::vector<std::string> copy_flags(const std::vector<std::string>& command, std::vector<std::string> more = {}) {
  std::vector<std::string> flags = {"--host-id", kHost, "--admin-token", kAdminToken};
  for (const std::string& arg : command) {
    flags.emplace_back("--after-session-command");
    flags.push_back(arg);
  }
  flags.insert(flags.end(), more.begin(), more.end());
  return with_small_sessions(flags);
}

// A session that fails at once; its token.
std::string start_failing_session(const ManagerUnderTest& manager, const std::string& uid) {
  const std::string token = token_from_redirect(manager.start("uid=" + uid + "&" + kFailingStart));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "failed"));
  return token;
}

}  // namespace

TEST_CASE("an ended session's folder is copied to the store, the same files, done after one try", "[manager][copy]") {
  TempDir data;
  TempDir store("rfbsim-copy-store");
  fs::create_directories(store.path() / kHost);
  ManagerUnderTest manager(data.path(),
                           copy_flags({"cp", "-r", "{folder}", store.path().string() + "/{host}/{folder_name}"}));
  const std::string token = token_from_redirect(manager.start("uid=copy-1&scenario=lab"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  CHECK(copy_columns(data.path(), token).state == "");  // nothing to copy while it runs
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);

  const CopyColumns copy = wait_for_copy(data.path(), token, "done", 30s);
  CHECK(copy.state == "done");
  CHECK(copy.attempts == 1);
  CHECK(copy.error == "");
  const fs::path folder = row->data_path;
  const fs::path copied = store.path() / kHost / folder.filename();
  const auto original = tree(folder);
  CHECK(original.count("manager.json") == 1);  // the copy came after the manager's record
  CHECK(original.count("session.log") == 1);
  CHECK(tree(copied) == original);
  // The command's output went beside the session folders, not into the one it copied.
  CHECK(fs::is_regular_file(data.path() / "copy-logs" / (folder.filename().string() + ".log")));

  // The admin API says so too.
  const auto list = nlohmann::json::parse(
      manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + kAdminToken}}).body, nullptr, false);
  REQUIRE_FALSE(list.is_discarded());
  const auto& sessions = list.is_object() ? list["recent"] : list;
  bool seen = false;
  for (const auto& s : sessions) {
    if (s.value("id", 0) != row->id) continue;
    seen = true;
    CHECK(s["copy_state"] == "done");
    CHECK(s["copy_attempts"] == 1);
    CHECK(s["copy_error"] == "");
  }
  CHECK(seen);
}

TEST_CASE("a copy that fails twice is tried again after its backoff and ends done after three tries",
          "[manager][copy][waits]") {
  TempDir data;
  TempDir store("rfbsim-copy-store");
  const fs::path runs = store.path() / "runs";
  // Counts its runs; the first two fail as an unreachable store would.
  const std::string script = write_script(store.path() / "flaky-copy.sh",
                                          "n=$(( $(cat '" + runs.string() + "' 2>/dev/null || echo 0) + 1 ))\n"
                                          "echo $n > '" + runs.string() + "'\n"
                                          "if [ $n -le 2 ]; then echo \"store unreachable (run $n)\" >&2; exit 3; fi\n"
                                          "exec cp -r \"$1\" \"$2\"\n");
  ManagerUnderTest manager(data.path(), copy_flags({script, "{folder}", store.path().string() + "/{folder_name}"}));
  const std::string token = start_failing_session(manager, "flaky-1");

  // 5 s after the first failure, 10 s after the second.
  const CopyColumns copy = wait_for_copy(data.path(), token, "done", 60s);
  CHECK(copy.state == "done");
  CHECK(copy.attempts == 3);
  CHECK(copy.error == "");
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const fs::path folder = row->data_path;
  CHECK(tree(store.path() / folder.filename()) == tree(folder));
  const std::string log = rfbsim::test::file_text(data.path() / "copy-logs" / (folder.filename().string() + ".log"));
  CHECK(log.find("--- try 1 at ") != std::string::npos);
  CHECK(log.find("store unreachable (run 1)") != std::string::npos);
  CHECK(log.find("store unreachable (run 2)") != std::string::npos);
  CHECK(log.find("--- try 3 at ") != std::string::npos);
}

TEST_CASE("a copy that always fails ends failed with its words recorded, and the manager carries on",
          "[manager][copy][waits]") {
  TempDir data;
  TempDir store("rfbsim-copy-store");
  // Slow to fail, so that a session's process exits (and is reaped) while a copy runs.
  const std::string script =
      write_script(store.path() / "broken-copy.sh", "sleep 2\necho \"store unreachable: $1\" >&2\nexit 3\n");
  ManagerUnderTest manager(data.path(), copy_flags({script, "session={session_id}"}, {"--after-session-retries", "1"}));
  const std::string first = start_failing_session(manager, "broken-1");
  const std::string second = start_failing_session(manager, "broken-2");

  const auto first_row = manager.row_for_token(first);
  const auto second_row = manager.row_for_token(second);
  REQUIRE(first_row);
  REQUIRE(second_row);
  // The supervisor reaped its own session (its exit status is the program's), the copier its command.
  CHECK(second_row->exit_status == "exit 2");
  for (const auto& row : {*first_row, *second_row}) {
    const CopyColumns copy = wait_for_copy(data.path(), row.token, "failed", 60s);
    CHECK(copy.state == "failed");
    CHECK(copy.attempts == 2);
    CHECK(copy.error == "exit 3: store unreachable: session=" + std::to_string(row.id));
  }
  CHECK(manager.get("/healthz").status == 200);
  const std::string next = token_from_redirect(manager.start("uid=after-broken&scenario=lab"));
  CHECK(next.size() == 32);
  CHECK(manager.wait_for_state(next, "running"));
}

TEST_CASE("a copy cut short by a killed manager is done by the next one", "[manager][copy]") {
  TempDir data;
  TempDir store("rfbsim-copy-store");
  const fs::path started = store.path() / "started";
  const std::string hanging =
      write_script(store.path() / "hanging-copy.sh", "echo $$ > '" + started.string() + "'\nexec sleep 60\n");
  std::string token;
  fs::path folder;
  {
    ManagerUnderTest manager(data.path(), copy_flags({hanging, "{folder}"}));
    token = start_failing_session(manager, "restart-1");
    folder = manager.row_for_token(token)->data_path;
    REQUIRE(rfbsim::test::eventually([&] { return !rfbsim::test::file_text(started).empty(); }, 20s));
    const CopyColumns running = copy_columns(data.path(), token);
    CHECK(running.state == "pending");
    CHECK(running.attempts == 0);
    manager.process().stop(SIGKILL, 10s);
    // The command died with the manager (PR_SET_PDEATHSIG), and its try was never recorded.
    const pid_t command = static_cast<pid_t>(std::stol(rfbsim::test::file_text(started)));
    CHECK(rfbsim::test::eventually([&] { return !rfbsim::test::process_exists(command); }, 10s));
  }
  CHECK(copy_columns(data.path(), token).state == "pending");

  ManagerUnderTest again(data.path(), copy_flags({"cp", "-r", "{folder}", store.path().string() + "/{folder_name}"}));
  const CopyColumns copy = wait_for_copy(data.path(), token, "done", 30s);
  CHECK(copy.state == "done");
  CHECK(copy.attempts == 1);
  CHECK(tree(store.path() / folder.filename()) == tree(folder));
}
