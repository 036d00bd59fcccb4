// SPDX-License-Identifier: GPL-2.0-or-later
// A session recorded by a real sim_rfb process (a real RFB client pressing keys over loopback, the process
// ended by SIGTERM) replays with the very same poses: the live loop and the replay apply the same inputs at
// the same ticks through the same StudySession.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>

#include <cmath>

#include "record/session_log.hpp"
#include "replay_fixtures.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"

using namespace rfbsim;
using test::SimProcess;

namespace {

// Holds a key for `held`, pumping the connection meanwhile so that updates keep flowing.
void hold_key(test::RfbTestClient& client, std::uint32_t keysym, std::chrono::milliseconds held) {
  client.send_key(keysym, true);
  client.pump_until([] { return false; }, held);
  client.send_key(keysym, false);
}

}  // namespace

TEST_CASE("a session recorded by a real sim_rfb with a client pressing keys replays with exactly the same poses") {
  const auto dir = test::fresh_dir("sim_rfb_keys");
  {
    SimProcess sim(test::sim_rfb_path(), {"--port", "0", "--scenario", "lab", "--data-dir", dir.string(), "--width",
                                          "320", "--height", "240", "--uid", "p-live"});
    {
      test::RfbTestClient client("127.0.0.1", sim.port());
      REQUIRE(client.wait_for_updates(1, std::chrono::seconds(20)));
      // Walk, turn while walking, walk on, raise the camera: the avatar moves and the task clock runs.
      hold_key(client, 'w', std::chrono::milliseconds(1200));
      client.send_key('w', true);
      hold_key(client, 'a', std::chrono::milliseconds(400));
      client.pump_until([] { return false; }, std::chrono::milliseconds(600));
      client.send_key('w', false);
      hold_key(client, 0xff52, std::chrono::milliseconds(300));  // Up
      client.pump_until([] { return false; }, std::chrono::milliseconds(500));
      // Ended while the viewer still watches, as sim_manager's expiry does. (A viewer who leaves first is
      // covered in-process: replay_check_test.cpp.)
      const int status = sim.stop(SIGTERM);
      REQUIRE(WIFEXITED(status));
      REQUIRE(WEXITSTATUS(status) == 0);
    }
  }

  // The log holds what the test needs: a clean end, a viewer, keys, and an avatar that moved.
  const sim::SessionLog log = sim::read_session(dir);
  REQUIRE(log.meta.end_tick.has_value());
  CHECK(log.meta.end_reason == "signal");
  int keys = 0, connects = 0, timers = 0;
  for (const sim::Event& e : log.events) {
    keys += e.type == "key" ? 1 : 0;
    connects += e.type == "client" && e.text("event") == "connect" ? 1 : 0;
    timers += e.type == "timer" ? 1 : 0;
  }
  CHECK(keys >= 8);
  CHECK(connects == 1);
  CHECK(timers == 1);
  const sim::TrajectoryRow& first = log.trajectory.front();
  const sim::TrajectoryRow& last_avatar = *std::find_if(log.trajectory.rbegin(), log.trajectory.rend(),
                                                        [](const sim::TrajectoryRow& r) { return r.kind == sim::AgentKind::Avatar; });
  REQUIRE(first.kind == sim::AgentKind::Avatar);
  CHECK(std::hypot(last_avatar.x - first.x, last_avatar.y - first.y) > 0.5);

  // The replay: same rows, same text, to the last digit.
  const auto out = test::fresh_dir("sim_rfb_keys_replay");
  const test::ReplayRun run = test::run_replay({dir.string(), "--check-only", "--out-dir", out.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(run.output.find("poses match the log: " + std::to_string(log.trajectory.size()) + " rows") != std::string::npos);
  CHECK(test::read_lines(out / "trajectories.csv") == test::read_lines(dir / "trajectories.csv"));
  // The replay's own events hold the same inputs at the same ticks, in the same order.
  const auto inputs = [](const sim::SessionLog& l) {
    std::vector<std::string> found;
    for (const sim::Event& e : l.events) {
      if (e.type == "key" || e.type == "client" || e.type == "timer" || e.type == "task") {
        found.push_back(std::to_string(e.tick) + " " + e.type + " " + e.fields.dump());
      }
    }
    return found;
  };
  CHECK(inputs(sim::read_session(out)) == inputs(log));
}
