// SPDX-License-Identifier: GPL-2.0-or-later
// The `task` section of scenario files: the shipped scenarios' tasks, defaults, and errors naming the key.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "scenario/scenario.hpp"

using namespace rfbsim::sim;

namespace {

const std::string kDir = RFBSIM_SCENARIO_DIR;

// A copy of the lab scenario with its task section replaced, in a temporary file beside the real one's map.
std::filesystem::path lab_with_task(const std::string& task_yaml, const std::string& name) {
  std::ifstream in(kDir + "/lab.yaml");
  std::stringstream whole;
  whole << in.rdbuf();
  std::string text = whole.str();
  text = text.substr(0, text.find("\ntask:"));
  const auto dir = std::filesystem::temp_directory_path() / "rfbsim_task_yaml";
  std::filesystem::create_directories(dir);
  // The map is named relative to the scenario file: point it at the shipped maps.
  const std::string::size_type at = text.find("map: maps/lab.yaml");
  text.replace(at, std::string("map: maps/lab.yaml").size(), "map: " + kDir + "/maps/lab.yaml");
  const auto file = dir / (name + ".yaml");
  std::ofstream(file) << text << "\n" << task_yaml;
  return file;
}

std::string load_error(const std::filesystem::path& file) {
  try {
    load_scenario(file);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("the study scenarios carry SEAN-EP's three tasks with their limits") {
  for (const char* name : {"lab", "warehouse"}) {
    const Scenario scenario = load_scenario(kDir + "/" + name + ".yaml");
    const TaskSpec& task = scenario.task;
    REQUIRE(task.steps.size() == 3);
    CHECK(task.time_limit == 240.0);
    CHECK(task.steps[0].type == TaskType::FindRobot);
    CHECK(task.steps[1].type == TaskType::FollowRobot);
    CHECK(task.steps[1].duration == 30.0);
    CHECK(task.steps[2].type == TaskType::Reach);
    CHECK(task.steps[2].distance == 0.3);
    REQUIRE(task.steps[2].target);
    REQUIRE(scenario.avatar_goal);
    CHECK(task.steps[2].target->x() == scenario.avatar_goal->x);
    CHECK(task.steps[2].target->y() == scenario.avatar_goal->y);
  }
}

TEST_CASE("the tutorial teaches the keys in the empty lab") {
  const Scenario scenario = load_scenario(kDir + "/tutorial.yaml");
  CHECK(scenario.crowd.count == 0);
  CHECK_FALSE(scenario.robot.present);
  REQUIRE(scenario.task.steps.size() == 4);
  CHECK(scenario.task.steps[0].type == TaskType::Walk);
  CHECK(scenario.task.steps[1].type == TaskType::Turn);
  CHECK(scenario.task.steps[2].type == TaskType::Camera);
  CHECK(scenario.task.steps[3].type == TaskType::Reach);
}

TEST_CASE("a goal given by the link moves the reach step's target with it") {
  Scenario scenario = load_scenario(kDir + "/lab.yaml");
  ScenarioOverrides overrides;
  overrides.avatar_goal = "4.0,4.0";
  apply_overrides(scenario, overrides);
  REQUIRE(scenario.task.steps[2].target);
  CHECK(scenario.task.steps[2].target->x() == 4.0);
  CHECK(scenario.task.steps[2].target->y() == 4.0);
}

TEST_CASE("task sections that cannot work are refused with the file and key") {
  const std::string unknown = load_error(lab_with_task("task:\n  steps:\n    - type: dance\n", "unknown_type"));
  CHECK(unknown.find("task.steps[0].type") != std::string::npos);
  CHECK(unknown.find("dance") != std::string::npos);
  const std::string landmark = load_error(lab_with_task("task:\n  steps:\n    - type: reach\n      landmark: sofa\n", "bad_landmark"));
  CHECK(landmark.find("sofa") != std::string::npos);
  const std::string tolerance =
      load_error(lab_with_task("task:\n  steps:\n    - type: walk\n      tolerance: 1\n", "bad_tolerance"));
  CHECK(tolerance.find("tolerance") != std::string::npos);
  const std::string limit = load_error(lab_with_task("task:\n  time_limit: -3\n  steps:\n    - type: walk\n", "bad_limit"));
  CHECK(limit.find("time_limit") != std::string::npos);
  const std::string empty = load_error(lab_with_task("task:\n  steps: []\n", "no_steps"));
  CHECK(empty.find("steps") != std::string::npos);
  const std::string typo = load_error(lab_with_task("task:\n  time_limt: 3\n  steps:\n    - type: walk\n", "typo"));
  CHECK(typo.find("time_limt") != std::string::npos);
}
