// SPDX-License-Identifier: GPL-2.0-or-later
// SEAN-EP's "robot within 0.45 m of the avatar" can happen here: a real sim_rfb process records a session
// in which a real RFB client holds W and walks the avatar into a robot that stands still, and the
// recorded data, read by the report's own code and by the sim_report binary, say the centres came within
// 0.45 m (bodies touching: 0.25 + 0.16 m) while the surfaces met.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "record/session_log.hpp"
#include "rfb_test_client.hpp"
#include "scratch_dir.hpp"
#include "session_metrics.hpp"
#include "session_samples.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::RfbTestClient;
using rfbsim::test::ScratchDir;
using rfbsim::test::SimProcess;

namespace {

// One CSV line split at commas: enough for sessions.csv's cells here, none of which is quoted.
std::vector<std::string> split_line(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// sessions.csv's only data row, by column name.
std::map<std::string, std::string> only_row(const std::string& csv) {
  std::stringstream in(csv);
  std::string header, row, extra;
  std::getline(in, header);
  std::getline(in, row);
  REQUIRE_FALSE(std::getline(in, extra));  // one session, one row
  const auto names = split_line(header);
  const auto cells = split_line(row);
  REQUIRE(names.size() == cells.size());
  std::map<std::string, std::string> out;
  for (std::size_t i = 0; i < names.size(); ++i) out[names[i]] = cells[i];
  return out;
}

}  // namespace

TEST_CASE("walking the avatar into a standing robot brings the centres within SEAN-EP's 0.45 m") {
  ScratchDir scratch("rfbsim_contact");
  const auto data = scratch.path() / "session";
  {
    SimProcess sim(rfbsim::test::sim_rfb_path(),
                   {"--port", "0", "--width", "320", "--height", "240", "--scenario", AVATAR_CONTACT_SCENARIO,
                    "--data-dir", data.string(), "--uid", "contact"});
    RfbTestClient client("127.0.0.1", sim.port());
    // The first picture starts the task's clock; then W is held until the session ends by itself.
    REQUIRE(client.wait_for_updates(1, 30s));
    client.send_key('w', true);
    // The task ends the session once the bodies have touched for 1 s; the server then closes the stream.
    client.pump_until([&] { return !client.connected(); }, 120s);
    const int status = sim.stop(0, 30s);  // no signal: waits for the exit the session's end brings
    REQUIRE(status != -1);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
  }

  // The recorded session, measured by the report's code.
  const rfbsim::sim::SessionLog log = rfbsim::sim::read_session(data);
  const rfbsim::report::SessionMetrics m = rfbsim::report::session_metrics(log, rfbsim::report::assemble_samples(log));
  CHECK(m.outcome == "completed");
  CHECK(m.avatar_radius == 0.25);
  REQUIRE(m.robot_radius);
  CHECK(*m.robot_radius == 0.16);
  REQUIRE(m.min_robot_avatar_distance);
  INFO("closest centres " << *m.min_robot_avatar_distance << " m, gap " << m.min_robot_avatar_gap.value_or(-1));
  CHECK(*m.min_robot_avatar_distance < 0.45);
  CHECK(m.robot_within_0_45);
  // Touching, not passing through: the physics lets the bodies sink into each other by millimetres only.
  CHECK(*m.min_robot_avatar_distance > 0.41 - 0.02);
  REQUIRE(m.min_robot_avatar_gap);
  CHECK(*m.min_robot_avatar_gap < 0.02);  // a collision by the 2 cm rule
  CHECK(m.robot_gap_within_0_45);
  CHECK(m.avatar_robot_contacts >= 1);

  // The sim_report binary says the same in sessions.csv.
  const auto out = scratch.path() / "report";
  const auto report = rfbsim::test::run_to_exit(SIM_REPORT_BINARY, {data.string(), "--out", out.string()}, 60s);
  INFO(report.output);
  REQUIRE(WIFEXITED(report.status));
  CHECK(WEXITSTATUS(report.status) == 0);
  const auto row = only_row(scratch.read("report/sessions.csv"));
  CHECK(row.at("robot_within_0_45") == "1");
  CHECK(row.at("robot_gap_within_0_45") == "1");
  CHECK(std::stod(row.at("min_robot_avatar_distance")) < 0.45);
}
