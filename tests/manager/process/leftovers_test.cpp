// SPDX-License-Identifier: GPL-2.0-or-later
// What a manager killed with SIGKILL leaves on the machine: its private folder of session sockets is found again
// by the next manager of the same data directory, cleared, and removed when that one stops; no folder of the
// killed one is left in /tmp.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;

namespace {

// The private socket folder `pid` holds: the folder of the lock it keeps open there ("" if none).
std::string socket_folder_of(pid_t pid) {
  std::error_code ec;
  for (const auto& fd : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
    std::error_code link_error;
    const std::filesystem::path target = std::filesystem::read_symlink(fd.path(), link_error);
    if (!link_error && target.filename() == ".lock" &&
        target.parent_path().filename().string().rfind("rfbsim-manager-", 0) == 0) {
      return target.parent_path().string();
    }
  }
  return {};
}

std::vector<std::string> entries_of(const std::string& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("kill -9 of a manager with 3 live sessions leaves no socket folder once its successor ran",
          "[manager]") {
  TempDir data;
  std::string killed_folder;
  {
    ManagerUnderTest manager(data.path(), with_small_sessions({}));
    for (const char* uid : {"left-1", "left-2", "left-3"}) {
      const std::string token = token_from_redirect(manager.start(std::string("uid=") + uid));
      REQUIRE(manager.wait_for_state(token, "running"));
    }
    killed_folder = socket_folder_of(manager.pid());
    REQUIRE_FALSE(killed_folder.empty());
    CHECK(entries_of(killed_folder) == std::vector<std::string>{".lock", "1.sock", "2.sock", "3.sock"});
    REQUIRE(manager.process().stop(SIGKILL) != -1);
  }
  // The killed manager could clear nothing: its sockets are still there.
  CHECK(entries_of(killed_folder).size() == 4);
  {
    rfbsim::test::ManagerOptions options;
    options.stop_signal = SIGTERM;  // a clean stop, which removes the folder
    ManagerUnderTest successor(data.path(), with_small_sessions({}), options);
    // The successor took the same folder and cleared the stale sockets before serving anything.
    CHECK(socket_folder_of(successor.pid()) == killed_folder);
    CHECK(entries_of(killed_folder) == std::vector<std::string>{".lock"});
    const std::string token = token_from_redirect(successor.start("uid=left-4"));
    REQUIRE(successor.wait_for_state(token, "running"));
    CHECK(entries_of(killed_folder) == std::vector<std::string>{".lock", "4.sock"});
    REQUIRE(successor.process().stop(SIGTERM, 20s) != -1);
  }
  std::error_code ec;
  CHECK_FALSE(std::filesystem::exists(killed_folder, ec));
}
