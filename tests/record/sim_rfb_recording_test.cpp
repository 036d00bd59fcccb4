// SPDX-License-Identifier: GPL-2.0-or-later
// Real sim_rfb processes recording a session: killed with SIGKILL they leave readable files up to two seconds
// before the kill; ended with SIGTERM they close session.json with the end; a viewer's connect is recorded hashed.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "http_client.hpp"
#include "record/session_log.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "status_tick.hpp"
#include "scratch_dir.hpp"

using nlohmann::json;
using rfbsim::test::current_tick;
using rfbsim::test::ScratchDir;
using rfbsim::test::SimProcess;

namespace {

// Complete lines only: a last line without its newline is a write the kill cut short.
std::vector<std::string> complete_lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t end = text.find('\n'); end != std::string::npos; end = text.find('\n', start)) {
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

// The simulation's tick now, from /status.json.
}  // namespace

TEST_CASE("sim_rfb killed with SIGKILL leaves readable session files up to two seconds before the kill") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "killed";
  SimProcess sim(rfbsim::test::sim_rfb_path(),
                 {"--port", "0", "--scenario", "lab", "--data-dir", dir.string(), "--uid", "p-killed"});
  // A participant walks for a while, so that there are inputs, moves and task events to lose.
  {
    rfbsim::test::RfbTestClient client("127.0.0.1", sim.port());
    REQUIRE(client.wait_for_updates(1, std::chrono::seconds(20)));
    client.send_key('w', true);
    client.pump_until([] { return false; }, std::chrono::milliseconds(2500));
    const std::uint64_t tick_before_kill = current_tick(sim.port());
    REQUIRE(tick_before_kill > 60);
    sim.stop(SIGKILL);

    // The project's own reader takes the folder as it is (a torn last line is dropped, not an error).
    const rfbsim::sim::SessionLog log = rfbsim::sim::read_session(dir);
    CHECK(log.meta.uid == "p-killed");
    CHECK_FALSE(log.meta.ended_at);  // it never ended cleanly, and says so
    CHECK_FALSE(log.meta.data_incomplete);
    REQUIRE_FALSE(log.trajectory.empty());
    // Lines reach the disk every half second, synced: at most two seconds (120 ticks) before the kill is lost.
    CHECK(log.trajectory.back().tick + 120 >= tick_before_kill);
    bool connect_seen = false, timer_seen = false, w_down = false;
    for (const rfbsim::sim::Event& event : log.events) {
      connect_seen = connect_seen || (event.type == "client" && event.text("event") == "connect");
      timer_seen = timer_seen || event.type == "timer";  // a task event: synced when it happened
      w_down = w_down || (event.type == "key" && event.integer("keysym") == 'w' && event.flag("down"));
    }
    CHECK(connect_seen);
    CHECK(timer_seen);
    CHECK(w_down);
  }
  // And so does a plain line-by-line reader.
  const auto rows = complete_lines(dir / "trajectories.csv");
  REQUIRE(rows.size() > 1);
  CHECK(rows.front() == "tick,time,kind,id,x,y,yaw,vx,vy");
  for (const std::string& line : complete_lines(dir / "events.jsonl")) CHECK_NOTHROW(json::parse(line));
}

TEST_CASE("sim_rfb ended with SIGTERM writes the end, and records a viewer with its address hashed") {
  ScratchDir scratch;
  const auto dir = scratch.path() / "terminated";
  SimProcess sim(rfbsim::test::sim_rfb_path(), {"--port", "0", "--scenario", "lab", "--data-dir", dir.string()});
  {
    rfbsim::test::RfbTestClient client("127.0.0.1", sim.port());
    REQUIRE(client.wait_for_updates(1, std::chrono::seconds(20)));
    client.send_key('w', true);
    client.pump_until([] { return false; }, std::chrono::milliseconds(300));
    client.send_key('w', false);
    client.pump_until([] { return false; }, std::chrono::milliseconds(300));
  }
  const int status = sim.stop(SIGTERM);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  const json session = json::parse(std::ifstream(dir / "session.json"));
  CHECK(session["end_reason"] == "signal");
  CHECK(session["ended_at"].is_string());
  CHECK(session["outcome"].is_null());
  bool connect_seen = false, timer_seen = false, w_down = false;
  for (const std::string& line : complete_lines(dir / "events.jsonl")) {
    const json event = json::parse(line);
    if (event["type"] == "client" && event["event"] == "connect") {
      connect_seen = true;
      CHECK(event["address"].get<std::string>().size() == 16);
      CHECK(event["address"].get<std::string>().find("127") == std::string::npos);
    }
    timer_seen = timer_seen || event["type"] == "timer";
    w_down = w_down || (event["type"] == "key" && event["keysym"] == 'w' && event["down"] == true);
  }
  CHECK(connect_seen);
  CHECK(timer_seen);
  CHECK(w_down);
  const auto lines = complete_lines(dir / "events.jsonl");
  CHECK(json::parse(lines.back())["reason"] == "signal");
}
