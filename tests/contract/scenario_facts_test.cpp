// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's scenario facts against sim_rfb's full reader: on every shipped scenario both must see the same
// spawn points, robot, control and task clock, since the manager checks links and durations with the facts and
// sim_rfb then runs the session with the scenario.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scenario/scenario.hpp"
#include "scenario/scenario_facts.hpp"

namespace sim = rfbsim::sim;

TEST_CASE("the facts agree with the full scenario reader on every shipped scenario") {
  std::size_t checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(RFBSIM_SCENARIO_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    INFO(entry.path());
    std::ifstream in(entry.path());
    std::ostringstream text;
    text << in.rdbuf();
    std::string error;
    const auto facts = sim::parse_scenario_facts(text.str(), entry.path().stem().string(), entry.path().string(), error);
    REQUIRE(facts);
    CHECK(error.empty());
    const sim::Scenario scenario = sim::load_scenario(entry.path());
    std::vector<std::string> spawns;
    for (const sim::SpawnPoint& spawn : scenario.spawns) spawns.push_back(spawn.name);
    CHECK(facts->spawns == spawns);
    CHECK(facts->has_robot == scenario.robot.present);
    CHECK(facts->robot_control == sim::robot_control_name(scenario.robot.control));
    CHECK(facts->has_task == !scenario.task.steps.empty());
    CHECK(facts->time_limit_s == scenario.task.time_limit);
    CHECK(facts->end_grace_s == scenario.task.end_grace);
    ++checked;
  }
  CHECK(checked >= 3);
}

TEST_CASE("the facts refuse a task clock outside the contract's bounds, naming file, line and key") {
  std::string error;
  CHECK_FALSE(sim::parse_scenario_facts("task:\n  time_limit: 86401\n", "s", "s.yaml", error));
  CHECK(error == "s.yaml:2: task.time_limit: expected seconds 1..86400");
  CHECK_FALSE(sim::parse_scenario_facts("task:\n  end_grace: -1\n", "s", "s.yaml", error));
  CHECK(error == "s.yaml:2: task.end_grace: expected seconds 0..3600");
}
