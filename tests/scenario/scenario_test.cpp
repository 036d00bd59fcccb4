// SPDX-License-Identifier: GPL-2.0-or-later
// The shipped scenarios load as documented, and overrides change exactly what they name.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scenario/scenario.hpp"

using namespace rfbsim::sim;

namespace {
const std::filesystem::path kScenarios = RFBSIM_SCENARIO_DIR;

const SpawnPoint& spawn(const Scenario& s, const std::string& name) {
  for (const auto& p : s.spawns) {
    if (p.name == name) return p;
  }
  FAIL("no spawn " << name);
  throw;
}
}  // namespace

TEST_CASE("the warehouse scenario is a 20 x 30 m hall with aisles of shelving and 15 people") {
  const Scenario s = load_scenario(kScenarios / "warehouse.yaml");
  CHECK(s.name == "warehouse");
  CHECK(s.map.width * s.map.resolution == Approx(21.0));
  CHECK(s.map.height * s.map.resolution == Approx(31.0));
  int shelves = 0;
  for (const Prop& p : s.props) shelves += p.kind == PropKind::Shelf ? 1 : 0;
  CHECK(shelves == 10);  // two blocks of five racks, written with `repeat`
  CHECK(s.crowd.count == 15);
  CHECK(s.crowd.goals.size() >= 10);
  CHECK(s.spawns.size() >= 8);
  REQUIRE(s.robot.present);
  CHECK(s.robot.mission.kind == MissionSpec::Kind::GoTo);
  // As in SEAN-EP, the robot goes to where the participant starts.
  CHECK(s.robot.mission.waypoints.at(0).x == s.avatar_start.x);
  CHECK(s.robot.mission.waypoints.at(0).y == s.avatar_start.y);
  REQUIRE(s.avatar_goal);
  CHECK(s.avatar_goal->name == "pickup");

  // Shelves block the obstacle grid but are not walls of the map.
  const World world = make_world(s);
  const Prop& rack = s.props.front();
  CHECK(world.obstacles.is_occupied_at(rack.x, rack.y));
  CHECK_FALSE(world.map.is_occupied_at(rack.x, rack.y));
  CHECK(world.avatar.pose.x == spawn(s, "dock").pose.x);
  REQUIRE(world.robot);
  CHECK(world.robot->pose.x == spawn(s, "north_middle").pose.x);
  // Every spawn point leaves room for a body.
  for (const auto& p : s.spawns) {
    INFO(p.name);
    CHECK_FALSE(world.obstacles.disc_hits_wall(p.pose.x, p.pose.y, 0.3));
  }
}

TEST_CASE("the lab scenario is a room of desks behind one doorway, with one pedestrian") {
  const Scenario s = load_scenario(kScenarios / "lab.yaml");
  int desks = 0;
  for (const Prop& p : s.props) desks += p.kind == PropKind::Desk ? 1 : 0;
  CHECK(desks == 13);
  CHECK(s.crowd.count == 1);
  REQUIRE(s.crowd.routes.size() == 1);
  CHECK(s.crowd.routes[0].size() == 5);
  const World world = make_world(s);
  // The corridor and the room connect only through the doorway: along y = 2.7 the wall is open only there.
  int open_cells = 0;
  for (double x = 0.6; x < 10.5; x += 0.05) open_cells += world.map.is_occupied_at(x, 2.7) ? 0 : 1;
  CHECK(open_cells * 0.05 == Approx(1.2).margin(0.1));
  bool has_printer = false;
  for (const Landmark& l : world.landmarks) has_printer = has_printer || l.name == "printer";
  CHECK(has_printer);
}

TEST_CASE("scenarios are found by name or path") {
  CHECK(find_scenario("warehouse", {kScenarios}) == kScenarios / "warehouse.yaml");
  CHECK(find_scenario((kScenarios / "lab.yaml").string(), {}) == kScenarios / "lab.yaml");
  try {
    (void)find_scenario("warhouse", {kScenarios});
    FAIL("a misspelt name was found");
  } catch (const ScenarioError& e) {
    CHECK_THAT(e.what(), Catch::Contains("warhouse") && Catch::Contains("warehouse") && Catch::Contains("lab"));
  }
  CHECK_THROWS_AS(find_scenario("../scenarios/warehouse", {kScenarios}), ScenarioError);
}

TEST_CASE("overrides move starts and goals by spawn name or x,y,yaw and reseed the crowd") {
  Scenario s = load_scenario(kScenarios / "warehouse.yaml");
  ScenarioOverrides o;
  o.avatar_start = "aisle_2";
  o.avatar_goal = "5.0,3.5";
  o.robot_start = "10.0,27.0,3.14";
  o.seed = 42;
  o.crowd_count = 3;
  apply_overrides(s, o);
  CHECK(s.avatar_start.x == spawn(s, "aisle_2").pose.x);
  REQUIRE(s.avatar_goal);
  CHECK(s.avatar_goal->x == 5.0);
  CHECK(s.robot.start.yaw == Approx(3.14));
  CHECK(s.seed == 42);
  CHECK(s.crowd.seed == 42);
  CHECK(s.crowd.count == 3);
  // The robot still heads for the participant's (new) start.
  CHECK(s.robot.mission.waypoints.at(0).x == s.avatar_start.x);

  const auto rejected = [&](ScenarioOverrides bad, const std::string& needle) {
    Scenario copy = load_scenario(kScenarios / "warehouse.yaml");
    try {
      apply_overrides(copy, bad);
      FAIL("accepted: " << needle);
    } catch (const ScenarioError& e) {
      INFO(e.what());
      CHECK_THAT(e.what(), Catch::Contains(needle));
    }
  };
  ScenarioOverrides unknown;
  unknown.avatar_start = "dok";
  rejected(unknown, "--avatar-start: 'dok' is neither a spawn point");
  ScenarioOverrides garbage;
  garbage.robot_goal = "1,2,3,4";
  rejected(garbage, "--robot-goal");
  ScenarioOverrides in_shelf;
  in_shelf.avatar_start = "3.0,13.5";  // inside the first rack
  rejected(in_shelf, "inside or against a wall or prop");
  ScenarioOverrides off_map;
  off_map.avatar_goal = "-5,3";
  rejected(off_map, "off the map");
  ScenarioOverrides crowd;
  crowd.crowd_count = 501;
  rejected(crowd, "--crowd");
}

TEST_CASE("robot.nav overrides the robot's parameters by ROS name") {
  const auto dir = std::filesystem::temp_directory_path() / ("rfbsim_nav_params_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::create_directories(dir / "maps");
  for (const char* f : {"lab.yaml", "lab.pgm"}) {
    std::filesystem::copy_file(std::string(RFBSIM_SCENARIO_DIR) + "/maps/" + f, dir / "maps" / f);
  }
  // The shipped lab with a nav block added to its robot section.
  std::ifstream in(std::string(RFBSIM_SCENARIO_DIR) + "/lab.yaml");
  std::ostringstream whole;
  whole << in.rdbuf();
  std::string text = whole.str();
  const std::string anchor = "robot:\n";
  const auto at = text.find(anchor);
  REQUIRE(at != std::string::npos);
  text.insert(at + anchor.size(),
              "  nav:\n"
              "    localization: ground_truth\n"
              "    dwa: {max_vel_x: 0.45, vth_samples: 30}\n"
              "    move_base: {xy_goal_tolerance: 0.2, recovery_behavior_enabled: false}\n"
              "    proxemic: {amplitude: 100, covariance: 0.1}\n"
              "    global_costmap: {inflation_radius: 0.5}\n");
  std::ofstream(dir / "lab.yaml", std::ios::trunc) << text;
  const Scenario s = load_scenario(dir / "lab.yaml");
  std::filesystem::remove_all(dir);
  const RobotParams& p = s.robot.params;
  CHECK(p.localization == Localization::GroundTruth);
  CHECK(p.dwa.max_vel_x == 0.45);
  CHECK(p.dwa.vth_samples == 30);
  CHECK(p.navigator.xy_goal_tolerance == 0.2);
  CHECK_FALSE(p.navigator.recovery_behavior_enabled);
  CHECK(p.global_costmap.proxemic.amplitude == 100.0);
  CHECK(p.local_costmap.proxemic.covariance == 0.1);  // one proxemic model for both costmaps
  CHECK(p.global_costmap.inflation.inflation_radius == 0.5);
  CHECK(p.local_costmap.inflation.inflation_radius == 0.45);  // untouched default
  // Everything else keeps docs/sources.md's defaults.
  CHECK(p.amcl.laser_max_beams == 30);
  CHECK(p.dwa.sim_time == 1.7);
}
