// SPDX-License-Identifier: GPL-2.0-or-later
// Real sim_rfb processes whose data folder fills up (the write-failure seam, and a real tiny tmpfs): the
// parent hears "data incomplete reason=..." once on the ready pipe, the session goes on serving frames and
// ends cleanly, and the folder reads back with the reason in session.json.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>
#include <regex>

#include "http_client.hpp"
#include "piped_sim.hpp"
#include "record/session_log.hpp"
#include "rfb_test_client.hpp"
#include "scratch_dir.hpp"
#include "sim_process.hpp"
#include "skip.hpp"
#include "small_tmpfs.hpp"
#include "status_tick.hpp"

using namespace std::chrono_literals;
using rfbsim::test::current_tick;
using rfbsim::test::PipedSim;
using rfbsim::test::ScratchDir;

namespace {

// Runs the lab scenario into `dir` until the pipe says the data is incomplete, checks that the session goes
// on (its clock advances and a viewer gets frames), ends it with SIGTERM, and returns the line's reason.
std::string run_until_incomplete(const std::filesystem::path& dir,
                                 const std::vector<std::pair<std::string, std::string>>& env,
                                 const std::filesystem::path& log) {
  PipedSim sim(rfbsim::test::sim_rfb_path(), {"--port", "0", "--scenario", "lab", "--data-dir", dir.string(), "--uid", "p-full"},
               env, log);
  const std::string ready = sim.await_line("ready ", 30s);
  REQUIRE_FALSE(ready.empty());
  const int port = std::stoi(ready.substr(6));
  const std::string notice = sim.await_line("data incomplete ", 60s);
  INFO("sim_rfb's log is in " << log.string());
  REQUIRE_FALSE(notice.empty());
  std::smatch match;
  REQUIRE(std::regex_match(notice, match, std::regex("data incomplete reason=(.+)")));
  const std::string reason = match[1];

  // The participant's session does not notice: the clock runs on and a viewer gets pictures.
  const std::uint64_t tick = current_tick(port);
  {
    rfbsim::test::RfbTestClient client("127.0.0.1", port);
    CHECK(client.wait_for_updates(1, 20s));
  }
  CHECK(current_tick(port) > tick);

  const int status = sim.stop(SIGTERM);
  REQUIRE(status != -1);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  // Said once, whatever else the pipe carried.
  int notices = 0;
  for (const std::string& line : sim.lines()) notices += line.rfind("data incomplete ", 0) == 0 ? 1 : 0;
  CHECK(notices == 1);
  return reason;
}

}  // namespace

TEST_CASE("sim_rfb whose data writes fail tells its parent once, keeps the session going, and notes why") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "seam";
  const std::string reason = run_until_incomplete(dir, {{"RFBSIM_TEST_FAIL_WRITES_AFTER", "4000"}}, scratch.path() / "sim.log");
  CHECK_THAT(reason, Catch::Matches("(trajectories\\.csv|events\\.jsonl): cannot write \\(No space left on device\\)"));

  const rfbsim::sim::SessionLog log = rfbsim::sim::read_session(dir);
  CHECK(log.meta.data_incomplete == reason);
  CHECK(log.meta.dropped_bytes > 0);
  CHECK(log.meta.end_reason == "signal");  // the end still reached session.json
  CHECK_FALSE(log.trajectory.empty());
  CHECK_FALSE(std::filesystem::exists(dir / "session.json.reserve"));
}

TEST_CASE("sim_rfb recording onto a real full disk (a 32 KiB tmpfs) tells its parent and notes why", "[waits]") {
  ScratchDir scratch;
  const auto mount_point = scratch.path() / "mnt";
  std::filesystem::create_directories(mount_point);
  rfbsim::test::SmallTmpfs tmpfs(mount_point, 32 * 1024);
  if (!tmpfs.mounted()) RFBSIM_SKIP(tmpfs.why_not());
  const auto dir = mount_point / "session";
  const std::string reason = run_until_incomplete(dir, {}, scratch.path() / "sim.log");
  CHECK_THAT(reason, Catch::Contains("No space left on device"));
  // The disk is still full, yet the reserved space let session.json take the reason and the end.
  const rfbsim::sim::SessionLog log = rfbsim::sim::read_session(dir);
  CHECK(log.meta.data_incomplete == reason);
  CHECK(log.meta.end_reason == "signal");
  CHECK_FALSE(log.trajectory.empty());
}
