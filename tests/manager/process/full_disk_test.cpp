// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager on a data directory that fills up: a real 2 MiB tmpfs, mounted in a mount namespace of this test's
// own (as root, or as the user's own root in a user namespace), filled to the last byte by a file. Nothing starts
// for a session the index cannot record, what the index refuses is served from memory and written once space
// returns, a restart on the still-full disk says what it could not mark, and no id names two folders.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sched.h>
#include <sys/mount.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "file_text.hpp"
#include "manager_process.hpp"
#include "skip.hpp"

using namespace std::chrono_literals;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerOptions;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;

namespace {

bool write_proc_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out.flush());
}

// Enters a mount namespace of this process's own, where mounts reach no one else: as root directly, else as the
// user's own root in a new user namespace. Whether it worked.
bool enter_private_mounts() {
  const uid_t uid = ::geteuid();
  const gid_t gid = ::getegid();
  if (::unshare(CLONE_NEWNS) != 0) {
    if (::unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) return false;
    if (!write_proc_file("/proc/self/setgroups", "deny") ||
        !write_proc_file("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n") ||
        !write_proc_file("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n")) {
      return false;
    }
  }
  // Mount events must not travel back to the machine's namespace (systemd makes / shared).
  return ::mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0;
}

// Writes zeros into `path` until the file system says it is full; the bytes written.
std::uintmax_t fill_until_full(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return 0;
  std::uintmax_t written = 0;
  const std::string block(4096, '\0');
  for (std::size_t size = block.size(); size > 0;) {
    const ssize_t n = ::write(fd, block.data(), size);
    if (n > 0) {
      written += static_cast<std::uintmax_t>(n);
    } else {
      size /= 2;  // ENOSPC: the last few bytes a smaller write may still take
    }
  }
  ::close(fd);
  return written;
}

// Lines of the manager's log that say a session of `uid` started its program.
bool started_program_for(const std::filesystem::path& log, const std::string& uid) {
  std::istringstream lines(rfbsim::test::file_text(log));
  for (std::string line; std::getline(lines, line);) {
    if (line.find("(uid " + uid + "): started") != std::string::npos) return true;
  }
  return false;
}

// Session ids named by more than one folder under data/sessions.
std::vector<std::string> ids_with_two_folders(const std::filesystem::path& data) {
  std::map<std::string, int> folders_by_id;
  for (const auto& entry : std::filesystem::directory_iterator(data / "sessions")) {
    const std::string name = entry.path().filename().string();
    ++folders_by_id[name.substr(0, name.find('-'))];
  }
  std::vector<std::string> twice;
  for (const auto& [id, count] : folders_by_id) {
    if (count > 1) twice.push_back(id);
  }
  return twice;
}

// Temporary files a failed write left anywhere under `data`.
int temporary_files(const std::filesystem::path& data) {
  int count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(data)) {
    count += entry.path().filename() == ".manager.json.tmp" ? 1 : 0;
  }
  return count;
}

bool in_ending_state(const std::string& state) {
  static const std::set<std::string> kEnded = {"ended", "abandoned", "interrupted", "failed", "expired", "crashed",
                                               "shutdown"};
  return kEnded.count(state) != 0;
}

}  // namespace

TEST_CASE("a data directory on a full 2 MiB tmpfs: nothing starts unrecorded, the index catches up, ids stay unique",
          "[manager][faults]") {
  if (!enter_private_mounts()) {
    RFBSIM_SKIP("cannot make a private mount namespace for a tmpfs (neither root nor unprivileged user namespaces)");
  }
  TempDir scratch;
  const std::filesystem::path data = scratch.path() / "data";
  std::filesystem::create_directories(data);
  REQUIRE(::mount("tmpfs", data.c_str(), "tmpfs", 0, "size=2m,mode=0700") == 0);
  const std::filesystem::path log = scratch.path() / "manager.log";
  ManagerOptions options;
  options.log_file = log;
  const auto flags = with_small_sessions({"--admin-token", kAdminToken, "--stop-grace-s", "1"});
  std::string ended_token;
  std::string live_token;
  int fillers = 0;
  // Fills what is free now; sim_rfb gives back the margin it reserved once its own writes fail, so the disk is
  // filled again before each step that needs it full.
  const auto fill = [&] { return fill_until_full((data / ("filler-" + std::to_string(++fillers))).string()); };
  {
    ManagerUnderTest manager(data, flags, options);
    ended_token = token_from_redirect(manager.start("uid=disk-ended"));
    live_token = token_from_redirect(manager.start("uid=disk-live"));
    REQUIRE(manager.wait_for_state(ended_token, "running"));
    REQUIRE(manager.wait_for_state(live_token, "running"));
    const auto ended_row = manager.row_for_token(ended_token);
    REQUIRE(ended_row);

    INFO("filled " << fill() << " bytes");
    // Links on the full disk: 503 with Retry-After, and no program for them.
    for (const char* uid : {"disk-full-1", "disk-full-2", "disk-full-3"}) {
      const auto response = manager.start(std::string("uid=") + uid);
      CAPTURE(uid, response.status, response.body.substr(0, 200));
      CHECK(response.status == 503);
      CHECK(response.headers.count("retry-after") == 1);
      CHECK(response.body.find("cannot save new sessions") != std::string::npos);
    }
    CHECK(manager.metric("rfbsim_rejections_total{reason=\"cannot_record\"}") == 3);
    CHECK(manager.metric("rfbsim_index_write_errors_total") >= 3);
    for (const char* uid : {"disk-full-1", "disk-full-2", "disk-full-3"}) CHECK_FALSE(started_program_for(log, uid));

    // A session ended while the disk is full: its state is served from memory whether or not the index took it.
    fill();
    REQUIRE(manager.end_session(ended_row->id, kAdminToken).status == 200);
    CHECK(rfbsim::test::eventually([&] { return manager.state_of(ended_token) == "abandoned"; }, 20s));
    // Killed while the disk is full: the index still calls the other session live.
    fill();
    REQUIRE(manager.process().stop(SIGKILL) != -1);
  }
  // Its sessions die with it; what they leave is filled too, so that the successor meets a full disk.
  std::this_thread::sleep_for(1s);
  fill();
  {
    // A successor on the still-full disk says that it could not mark the session interrupted.
    ManagerUnderTest successor(data, flags, options);
    CHECK(rfbsim::test::file_text(log).find("but the index took only 0 of them") != std::string::npos);
    // Space returns: the refused writes catch up without a restart.
    for (int i = 1; i <= fillers; ++i) std::filesystem::remove(data / ("filler-" + std::to_string(i)));
    CHECK(successor.wait_for_row(live_token, [](const auto& row) { return row.state == "interrupted"; }, 40s));
    // New links start again.
    const std::string token = token_from_redirect(successor.start("uid=disk-after"));
    REQUIRE(token.size() == 32);
    CHECK(successor.wait_for_state(token, "running"));
    REQUIRE(successor.process().stop(SIGKILL) != -1);
  }
  {
    ManagerUnderTest third(data, flags, options);
    for (const auto& row : third.index_rows()) {
      CAPTURE(row.id, row.uid, row.state);
      CHECK(in_ending_state(row.state));
    }
    CHECK(ids_with_two_folders(data).empty());
    CHECK(temporary_files(data) == 0);
  }
  ::umount2(data.c_str(), MNT_DETACH);
}
