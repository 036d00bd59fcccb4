// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "scratch_dir.hpp"
#include "admission/start_request.hpp"

using rfbsim::manager::is_identifier;
using rfbsim::manager::is_pose;
using rfbsim::manager::kOverrideParams;
using rfbsim::manager::parse_query;
using rfbsim::manager::parse_start_request;
using rfbsim::manager::QueryParams;
using rfbsim::manager::scenario_argument;
using rfbsim::manager::scenario_names;
using rfbsim::manager::StartParse;

namespace {

const std::vector<std::string> kScenarios = {"warehouse", "lab"};

// A valid link with one parameter replaced (or added).
StartParse parse_with(const std::string& name, const std::string& value) {
  QueryParams params = {{"uid", "p01"}, {"scenario", "lab"}};
  bool replaced = false;
  for (auto& param : params) {
    if (param.first == name) {
      param.second = value;
      replaced = true;
    }
  }
  if (!replaced) params.emplace_back(name, value);
  return parse_start_request(params, kScenarios);
}

bool accepted(const std::string& name, const std::string& value) { return parse_with(name, value).request.has_value(); }

// The seed a link with this seed value gives; nothing when refused or absent.
std::optional<std::uint64_t> seed_of(const std::string& value) {
  const StartParse parsed = parse_with("seed", value);
  return parsed.request ? parsed.request->seed : std::nullopt;
}

}  // namespace

TEST_CASE("a minimal link gives the uid and the default scenario, no seed and no overrides") {
  const StartParse parsed = parse_start_request({{"uid", "p01"}}, kScenarios);
  REQUIRE(parsed.request);
  CHECK(parsed.error.empty());
  CHECK(parsed.request->uid == "p01");
  CHECK(parsed.request->scenario == "warehouse");
  CHECK_FALSE(parsed.request->seed);
  CHECK(parsed.request->overrides.empty());
}

TEST_CASE("a full link gives every value") {
  const StartParse parsed = parse_start_request({{"uid", "P-01_x"},
                                                 {"scenario", "lab"},
                                                 {"seed", "18446744073709551615"},
                                                 {"crowd", "500"},
                                                 {"avatar_start", "1.5,-2,0.25"}},
                                                kScenarios);
  REQUIRE(parsed.request);
  CHECK(parsed.request->uid == "P-01_x");
  CHECK(parsed.request->scenario == "lab");
  REQUIRE(parsed.request->seed);
  CHECK(*parsed.request->seed == 18446744073709551615ULL);
  const std::vector<std::pair<std::string, std::string>> overrides = {{"avatar_start", "1.5,-2,0.25"},
                                                                      {"crowd", "500"}};
  CHECK(parsed.request->overrides == overrides);
}

TEST_CASE("overrides come out in the order of kOverrideParams whatever the link's order") {
  const StartParse parsed = parse_start_request({{"crowd", "3"},
                                                 {"robot_goal", "goal_b"},
                                                 {"uid", "p01"},
                                                 {"avatar_goal", "0,0,0"},
                                                 {"robot_start", "dock"},
                                                 {"avatar_start", "start_a"}},
                                                kScenarios);
  REQUIRE(parsed.request);
  const std::vector<std::pair<std::string, std::string>> overrides = {{"avatar_start", "start_a"},
                                                                      {"avatar_goal", "0,0,0"},
                                                                      {"robot_start", "dock"},
                                                                      {"robot_goal", "goal_b"},
                                                                      {"crowd", "3"}};
  CHECK(parsed.request->overrides == overrides);
}

TEST_CASE("the override parameters and their sim_rfb flags") {
  REQUIRE(kOverrideParams.size() == 7);
  CHECK(std::string(kOverrideParams[0].name) == "avatar_start");
  CHECK(std::string(kOverrideParams[0].flag) == "--avatar-start");
  CHECK(std::string(kOverrideParams[1].name) == "avatar_goal");
  CHECK(std::string(kOverrideParams[1].flag) == "--avatar-goal");
  CHECK(std::string(kOverrideParams[2].name) == "robot_start");
  CHECK(std::string(kOverrideParams[2].flag) == "--robot-start");
  CHECK(std::string(kOverrideParams[3].name) == "robot_goal");
  CHECK(std::string(kOverrideParams[3].flag) == "--robot-goal");
  CHECK(std::string(kOverrideParams[4].name) == "crowd");
  CHECK(std::string(kOverrideParams[4].flag) == "--crowd");
  CHECK(std::string(kOverrideParams[5].name) == "robot_control");
  CHECK(std::string(kOverrideParams[5].flag) == "--robot-control");
  CHECK(std::string(kOverrideParams[6].name) == "camera");
  CHECK(std::string(kOverrideParams[6].flag) == "--camera");
}

TEST_CASE("camera is third_person or first_person, exactly, and needs no robot or spawn point") {
  for (const char* value : {"third_person", "first_person"}) {
    const StartParse parsed = parse_with("camera", value);
    REQUIRE(parsed.request);
    CHECK(parsed.request->overrides == std::vector<std::pair<std::string, std::string>>{{"camera", value}});
    // An identifier, yet not a pose: the scenario's spawn points are not asked about it.
    rfbsim::manager::ScenarioFacts facts;
    facts.name = "lab";
    facts.spawns = {"door"};
    const StartParse checked = parse_start_request({{"uid", "p01"}, {"scenario", "lab"}, {"camera", value}},
                                                   kScenarios, {facts});
    CHECK(checked.request);
    CHECK(checked.error.empty());
  }
  for (const char* value : {"", "First_person", "first-person", "first_person ", "overhead", "1,2,0"}) {
    INFO(value);
    CHECK(parse_with("camera", value).error ==
          "camera '" + std::string(value) + "' is not valid: use third_person or first_person");
  }
}

TEST_CASE("robot_control is builtin or external, exactly") {
  for (const char* value : {"builtin", "external"}) {
    const StartParse parsed = parse_with("robot_control", value);
    REQUIRE(parsed.request);
    CHECK(parsed.request->overrides == std::vector<std::pair<std::string, std::string>>{{"robot_control", value}});
  }
  for (const char* value : {"", "External", "extern", "builtin ", "dock", "1,2,0", "external,builtin"}) {
    INFO(value);
    CHECK(parse_with("robot_control", value).error ==
          "robot_control '" + std::string(value) + "' is not valid: use builtin or external");
  }
  // Last in the fixed order, whatever the link's order.
  const StartParse parsed =
      parse_start_request({{"uid", "p01"}, {"robot_control", "external"}, {"crowd", "3"}}, kScenarios);
  REQUIRE(parsed.request);
  CHECK(parsed.request->overrides ==
        std::vector<std::pair<std::string, std::string>>{{"crowd", "3"}, {"robot_control", "external"}});
}

TEST_CASE("sig is ignored by the request check") {
  const StartParse parsed = parse_start_request({{"uid", "p01"}, {"sig", "not even hex"}}, kScenarios);
  REQUIRE(parsed.request);
  CHECK(parsed.request->overrides.empty());
}

TEST_CASE("a bad uid is refused") {
  CHECK(accepted("uid", std::string(64, 'a')));
  CHECK_FALSE(accepted("uid", std::string(65, 'a')));
  CHECK_FALSE(accepted("uid", ""));
  CHECK_FALSE(accepted("uid", "a/b"));
  CHECK_FALSE(accepted("uid", ".."));
  CHECK_FALSE(accepted("uid", "a.b"));
  CHECK_FALSE(accepted("uid", "a b"));
  CHECK_FALSE(accepted("uid", "\xC3\xA9"));
  CHECK(parse_with("uid", "a/b").error == "uid 'a/b' is not valid: use 1 to 64 letters, digits, '-' or '_'");
}

TEST_CASE("a uid of percent-encoded dots is refused once decoded") {
  std::string error;
  const auto params = parse_query("uid=%2e%2e&scenario=lab", error);
  REQUIRE(params);
  const StartParse parsed = parse_start_request(*params, kScenarios);
  CHECK_FALSE(parsed.request);
  CHECK(parsed.error == "uid '..' is not valid: use 1 to 64 letters, digits, '-' or '_'");
}

TEST_CASE("a long bad value is cut short in the message") {
  const StartParse parsed = parse_with("uid", std::string(65, 'a'));
  CHECK(parsed.error == "uid '" + std::string(40, 'a') + "...' is not valid: use 1 to 64 letters, digits, '-' or '_'");
}

TEST_CASE("a link without uid is refused") {
  const StartParse parsed = parse_start_request({{"scenario", "lab"}}, kScenarios);
  CHECK_FALSE(parsed.request);
  CHECK(parsed.error == "the link has no uid (participant id)");
}

TEST_CASE("a scenario that is not offered is refused") {
  CHECK(accepted("scenario", "warehouse"));
  CHECK_FALSE(accepted("scenario", "office"));
  CHECK_FALSE(accepted("scenario", "../etc"));
  CHECK_FALSE(accepted("scenario", "Lab"));
  CHECK_FALSE(accepted("scenario", ""));
  CHECK(parse_with("scenario", "../etc").error == "scenario '../etc' is not offered here (allowed: warehouse, lab)");
}

TEST_CASE("a scenario list entry that is not an identifier cannot be asked for") {
  // Config validation refuses such entries; the request check does not rely on it.
  const StartParse parsed = parse_start_request({{"uid", "p01"}, {"scenario", "../etc"}}, {"../etc"});
  CHECK_FALSE(parsed.request);
}

TEST_CASE("where no scenario is offered a link needs only uid, and one that names a scenario is refused") {
  // Session kinds rfb and x11 without a scenarios list: a program's scenarios are its own.
  const StartParse parsed = parse_start_request({{"uid", "p01"}}, {});
  REQUIRE(parsed.request);
  CHECK(parsed.request->uid == "p01");
  CHECK(parsed.request->scenario.empty());
  const StartParse named = parse_start_request({{"uid", "p01"}, {"scenario", "warehouse"}}, {});
  CHECK_FALSE(named.request);
  CHECK(named.error ==
        "scenario 'warehouse' is not offered here: this server's program has no scenarios, and its links need only uid");
  CHECK_FALSE(parse_start_request({{"scenario", "x"}}, {}).request);  // still no uid, still refused
}

TEST_CASE("seeds are whole decimal numbers that fit 64 bits") {
  CHECK(seed_of("0") == std::uint64_t{0});
  CHECK(seed_of("0042") == std::uint64_t{42});
  CHECK(seed_of("18446744073709551615") == 18446744073709551615ULL);
  CHECK_FALSE(accepted("seed", "18446744073709551616"));
  CHECK_FALSE(accepted("seed", "99999999999999999999"));
  CHECK_FALSE(accepted("seed", "-1"));
  CHECK_FALSE(accepted("seed", "+1"));
  CHECK_FALSE(accepted("seed", "1e3"));
  CHECK_FALSE(accepted("seed", " 12"));
  CHECK_FALSE(accepted("seed", "12 "));
  CHECK_FALSE(accepted("seed", "0x10"));
  CHECK_FALSE(accepted("seed", "1.0"));
  CHECK_FALSE(accepted("seed", ""));
  CHECK(parse_with("seed", "-1").error ==
        "seed '-1' is not valid: use a whole number 0..18446744073709551615");
}

TEST_CASE("poses are spawn names or three strict decimals within bounds") {
  SECTION("valid") {
    CHECK(is_pose("dock_a"));
    CHECK(is_pose("start-1"));
    CHECK(is_pose("1,2,3"));
    CHECK(is_pose("-1.5,0.25,-3.0"));
    CHECK(is_pose("10000,-10000,7"));
    CHECK(is_pose("0,0,-7"));
  }
  SECTION("invalid") {
    CHECK_FALSE(is_pose(""));
    CHECK_FALSE(is_pose("1,2"));
    CHECK_FALSE(is_pose("1,2,3,4"));
    CHECK_FALSE(is_pose("1,,2"));
    CHECK_FALSE(is_pose(",1,2"));
    CHECK_FALSE(is_pose("1,2,"));
    CHECK_FALSE(is_pose("nan,1,0"));
    CHECK_FALSE(is_pose("inf,1,0"));
    CHECK_FALSE(is_pose("1e2,0,0"));
    CHECK_FALSE(is_pose("10001,0,0"));
    CHECK_FALSE(is_pose("0,-10000.5,0"));
    CHECK_FALSE(is_pose("0,0,8"));
    CHECK_FALSE(is_pose("0,0,7.01"));
    CHECK_FALSE(is_pose("+1,0,0"));
    CHECK_FALSE(is_pose(" 1,0,0"));
    CHECK_FALSE(is_pose("1.,0,0"));
    CHECK_FALSE(is_pose(".5,0,0"));
    CHECK_FALSE(is_pose("-,0,0"));
    CHECK_FALSE(is_pose("0x1,0,0"));
    CHECK_FALSE(is_pose("1,2;3"));
    CHECK_FALSE(is_pose("dock a"));
  }
}

TEST_CASE("every pose parameter is checked") {
  for (const char* name : {"avatar_start", "avatar_goal", "robot_start", "robot_goal"}) {
    INFO(name);
    CHECK(accepted(name, "dock"));
    CHECK(accepted(name, "1,2,0.5"));
    CHECK_FALSE(accepted(name, "1,2"));
    CHECK_FALSE(accepted(name, "0,0,8"));
  }
  CHECK(parse_with("robot_goal", "1,2").error ==
        "robot_goal '1,2' is not valid: use a spawn point's name or x,y,yaw in metres and radians");
}

TEST_CASE("crowd is a whole number 0..500") {
  CHECK(accepted("crowd", "0"));
  CHECK(accepted("crowd", "500"));
  CHECK_FALSE(accepted("crowd", "501"));
  CHECK_FALSE(accepted("crowd", "-1"));
  CHECK_FALSE(accepted("crowd", "abc"));
  CHECK_FALSE(accepted("crowd", ""));
  CHECK_FALSE(accepted("crowd", "1.5"));
  CHECK_FALSE(accepted("crowd", "dock"));   // not a pose parameter
  CHECK(parse_with("crowd", "501").error == "crowd '501' is not valid: use a whole number 0..500");
}

TEST_CASE("an unknown parameter is refused") {
  const StartParse parsed = parse_with("debug", "1");
  CHECK_FALSE(parsed.request);
  CHECK(parsed.error == "unknown parameter 'debug'");
  CHECK_FALSE(accepted("Uid", "p02"));
  CHECK_FALSE(accepted("seed ", "1"));
}

TEST_CASE("is_identifier allows 1 to 64 letters, digits, minus and underscore") {
  CHECK(is_identifier("a"));
  CHECK(is_identifier("Az09-_"));
  CHECK(is_identifier(std::string(64, 'z')));
  CHECK_FALSE(is_identifier(""));
  CHECK_FALSE(is_identifier(std::string(65, 'z')));
  CHECK_FALSE(is_identifier("a.b"));
  CHECK_FALSE(is_identifier("a/b"));
  CHECK_FALSE(is_identifier("a=b"));
  CHECK_FALSE(is_identifier("a~b"));
}

TEST_CASE("scenario names and arguments come from NAME and NAME=FILE entries") {
  const std::vector<std::string> entries = {"warehouse", "lab=/srv/scenarios/lab.yaml", "empty="};
  CHECK(scenario_names(entries) == std::vector<std::string>{"warehouse", "lab", "empty"});
  CHECK(scenario_argument(entries, "warehouse") == "warehouse");
  CHECK(scenario_argument(entries, "lab") == "/srv/scenarios/lab.yaml");
  CHECK(scenario_argument(entries, "empty").empty());
  CHECK(scenario_argument(entries, "office") == "office");
  CHECK(scenario_argument(entries, "lab=/srv/scenarios/lab.yaml") == "lab=/srv/scenarios/lab.yaml");
  CHECK(scenario_names({}).empty());
}

TEST_CASE("a link naming a NAME=FILE scenario by its name is accepted") {
  const std::vector<std::string> entries = {"warehouse", "lab=/srv/lab.yaml"};
  const StartParse parsed = parse_start_request({{"uid", "p01"}, {"scenario", "lab"}}, scenario_names(entries));
  REQUIRE(parsed.request);
  CHECK(parsed.request->scenario == "lab");
  CHECK_FALSE(parse_start_request({{"uid", "p01"}, {"scenario", "lab=/srv/lab.yaml"}}, scenario_names(entries))
                  .request);
}

TEST_CASE("completion codes t1 and t2 are identifiers, kept apart from the scenario overrides") {
  const StartParse parsed =
      parse_start_request({{"uid", "p01"}, {"t1", "C1A2B3"}, {"t2", "T-9_x"}, {"crowd", "2"}}, kScenarios);
  REQUIRE(parsed.request);
  CHECK(parsed.request->code_success == "C1A2B3");
  CHECK(parsed.request->code_timeout == "T-9_x");
  CHECK(parsed.request->overrides == std::vector<std::pair<std::string, std::string>>{{"crowd", "2"}});
  CHECK_FALSE(accepted("t1", "a b"));
  CHECK_FALSE(accepted("t2", "<script>"));
  CHECK_FALSE(accepted("t1", ""));
  CHECK_FALSE(accepted("t2", std::string(65, 'x')));
  CHECK(parse_with("t1", "x;rm").error.find("t1") != std::string::npos);
}

TEST_CASE("exp is a Unix time in whole seconds, and nothing else") {
  const StartParse parsed = parse_with("exp", "1798761600");
  REQUIRE(parsed.request);
  CHECK(parsed.request->expires_at == std::uint64_t{1798761600});
  CHECK_FALSE(parse_start_request({{"uid", "p01"}}, kScenarios).request->expires_at);
  for (const char* bad : {"", "-1", "+5", "1e9", " 17", "17 ", "0x10", "99999999999999999999"}) {
    INFO(bad);
    const StartParse refused = parse_with("exp", bad);
    CHECK_FALSE(refused.request);
    CHECK(refused.error.find("exp '") == 0);
  }
}

TEST_CASE("a crowd size is digits only: no sign, not even on zero") {
  CHECK(accepted("crowd", "0"));
  CHECK(accepted("crowd", "500"));
  CHECK_FALSE(accepted("crowd", "-0"));
  CHECK_FALSE(accepted("crowd", "+1"));
  CHECK_FALSE(accepted("crowd", "501"));
}

// --- The offered scenarios' facts, and links checked against them ---

namespace {

using rfbsim::manager::load_scenario_facts;
using rfbsim::manager::parse_scenario_facts;
using rfbsim::manager::ScenarioFacts;

// A scenario as the warehouse writes one, cut to the keys the manager reads (the rest is sim_rfb's).
constexpr const char* kDepotYaml = R"(name: depot
map: maps/depot.yaml
spawns:
  dock:   [10.0, 2.8, 1.5708]
  aisle_1: [4.75, 13.5, 1.5708]
  office: [3.5, 29.3, -1.5708]
robot:
  start: office
task:
  time_limit: 240
  end_grace: 15
  steps: [{type: reach}]
)";

ScenarioFacts depot_facts() {
  std::string error;
  auto facts = parse_scenario_facts(kDepotYaml, "depot", "depot.yaml", error);
  REQUIRE(facts);
  return *facts;
}

std::string facts_error(const std::string& yaml) {
  std::string error;
  CHECK_FALSE(parse_scenario_facts(yaml, "s", "/srv/s.yaml", error));
  return error;
}

}  // namespace

TEST_CASE("a scenario file gives its spawn names, whether it has a robot, and its task's limits") {
  const ScenarioFacts facts = depot_facts();
  CHECK(facts.name == "depot");
  CHECK(facts.file == "depot.yaml");
  CHECK(facts.spawns == std::vector<std::string>{"dock", "aisle_1", "office"});  // in file order
  CHECK(facts.has_robot);
  CHECK(facts.has_task);
  CHECK(facts.time_limit_s == 240.0);
  CHECK(facts.end_grace_s == 15.0);

  // Without those keys: no spawns, no robot, no task; a task without limits has sim_rfb's defaults.
  std::string error;
  const auto bare = parse_scenario_facts("name: bare\nmap: m.yaml\n", "bare", "bare.yaml", error);
  REQUIRE(bare);
  CHECK(bare->spawns.empty());
  CHECK_FALSE(bare->has_robot);
  CHECK_FALSE(bare->has_task);
  CHECK(facts.robot_control == "builtin");
  // A robot's own robot.control (issue 20): who drives it unless a link or the ros section says otherwise.
  const auto driven = parse_scenario_facts("robot:\n  start: dock\n  control: external\n", "d", "d.yaml", error);
  REQUIRE(driven);
  CHECK(driven->robot_control == "external");
  const auto plain_task = parse_scenario_facts("task:\n  steps: [{type: reach}]\n", "t", "t.yaml", error);
  REQUIRE(plain_task);
  CHECK(plain_task->has_task);
  CHECK(plain_task->time_limit_s == 240.0);
  CHECK(plain_task->end_grace_s == 15.0);
  const auto tutorial = parse_scenario_facts("task:\n  time_limit: 180.5\n  end_grace: 0\n", "t", "t.yaml", error);
  REQUIRE(tutorial);
  CHECK(tutorial->time_limit_s == 180.5);
  CHECK(tutorial->end_grace_s == 0.0);
}

TEST_CASE("a spawn name no link can carry is left out of the facts, not an error") {
  std::string error;
  const auto facts = parse_scenario_facts("spawns:\n  a b: [1, 2]\n  dock: [3, 4, 0]\n", "s", "s.yaml", error);
  REQUIRE(facts);
  CHECK(error.empty());
  CHECK(facts->spawns == std::vector<std::string>{"dock"});
}

TEST_CASE("a malformed scenario file is an error naming the file, the line and the key") {
  CHECK(facts_error("task:\n  time_limit: soon\n") == "/srv/s.yaml:2: task.time_limit: expected seconds 1..86400");
  CHECK(facts_error("task:\n  time_limit: 0\n") == "/srv/s.yaml:2: task.time_limit: expected seconds 1..86400");
  CHECK(facts_error("task:\n  time_limit: 86401\n") == "/srv/s.yaml:2: task.time_limit: expected seconds 1..86400");
  CHECK(facts_error("task:\n  end_grace: -1\n") == "/srv/s.yaml:2: task.end_grace: expected seconds 0..3600");
  CHECK(facts_error("task:\n  end_grace: [1]\n") == "/srv/s.yaml:2: task.end_grace: expected seconds 0..3600");
  CHECK(facts_error("task: 240\n") == "/srv/s.yaml:1: task: expected a mapping (time_limit, end_grace, steps)");
  CHECK(facts_error("name: x\nspawns: [a, b]\n") == "/srv/s.yaml:2: spawns: expected a mapping of names to poses");
  CHECK(facts_error("- a\n- b\n") == "/srv/s.yaml: expected a mapping of scenario keys");
  CHECK(facts_error("") == "/srv/s.yaml: expected a mapping of scenario keys");
  CHECK_THAT(facts_error("spawns: {a: [1, 2]\n"), Catch::StartsWith("/srv/s.yaml:"));  // not YAML at all
}

TEST_CASE("the offered scenarios' files are found as sim_rfb finds them, and a named file must be readable") {
  rfbsim::test::ScratchDir first;
  rfbsim::test::ScratchDir second;
  first.write("depot.yaml", kDepotYaml);
  second.write("depot.yaml", "spawns: {elsewhere: [1, 1, 0]}\n");  // found second: not read
  second.write("yard.yaml", "spawns: {gate: [1, 1, 0]}\n");
  const std::string own = second.write("mine.yaml", "task: {time_limit: 60, steps: [{type: reach}]}\n");
  std::string error;
  std::vector<std::string> missing;
  const auto facts = load_scenario_facts({"depot", "yard", "ghost", "custom=" + own},
                                         {first.path(), second.path()}, error, missing);
  CHECK(error.empty());
  CHECK(missing == std::vector<std::string>{"ghost"});  // not found by name: left to sim_rfb, with a warning
  REQUIRE(facts.size() == 3);
  CHECK(facts[0].name == "depot");
  CHECK(facts[0].spawns == std::vector<std::string>{"dock", "aisle_1", "office"});
  CHECK(facts[0].file == (first.path() / "depot.yaml").string());
  CHECK(facts[1].name == "yard");
  CHECK(facts[1].spawns == std::vector<std::string>{"gate"});
  CHECK(facts[2].name == "custom");
  CHECK(facts[2].time_limit_s == 60.0);

  // A file the config names must be there; a malformed one stops the list with its error.
  missing.clear();
  load_scenario_facts({"depot", "custom=" + (second.path() / "nope.yaml").string()}, {first.path()}, error, missing);
  CHECK(error == "scenarios: custom=" + (second.path() / "nope.yaml").string() + ": cannot read " +
                     (second.path() / "nope.yaml").string());
  error.clear();
  load_scenario_facts({"custom=" + second.path().string()}, {}, error, missing);  // a folder is no file
  CHECK_THAT(error, Catch::StartsWith("scenarios: custom=" + second.path().string() + ": cannot read"));
  error.clear();
  const std::string broken = second.write("broken.yaml", "task: {time_limit: never}\n");
  load_scenario_facts({"broken=" + broken}, {}, error, missing);
  CHECK(error == broken + ":1: task.time_limit: expected seconds 1..86400");
}

TEST_CASE("a link naming a spawn point its scenario lacks is refused, before any session starts") {
  const std::vector<ScenarioFacts> facts = {depot_facts()};
  const std::vector<std::string> names = {"depot", "lab"};
  const auto parse = [&](const QueryParams& params) { return parse_start_request(params, names, facts); };

  const StartParse good = parse({{"uid", "p01"}, {"scenario", "depot"}, {"avatar_start", "dock"},
                                 {"avatar_goal", "office"}, {"robot_start", "aisle_1"}, {"robot_goal", "1.5,2,0"},
                                 {"crowd", "3"}});
  REQUIRE(good.request);
  CHECK(good.request->overrides.size() == 5);

  for (const char* param : {"avatar_start", "avatar_goal", "robot_start", "robot_goal"}) {
    const StartParse bad = parse({{"uid", "p01"}, {"scenario", "depot"}, {param, "dok"}});
    CHECK_FALSE(bad.request);
    CHECK(bad.error == std::string(param) +
                           " 'dok' is not a spawn point of depot (known: dock, aisle_1, office; or give x,y,yaw)");
  }
  // The default scenario is the first offered; its spawns are checked alike.
  CHECK(parse({{"uid", "p01"}, {"avatar_start", "aisle_9"}}).error ==
        "avatar_start 'aisle_9' is not a spawn point of depot (known: dock, aisle_1, office; or give x,y,yaw)");
  // A scenario without facts (not found by name) is checked for form only, as before.
  CHECK(parse({{"uid", "p01"}, {"scenario", "lab"}, {"avatar_start", "anything"}}).request);
  // The form is checked first, with its own message.
  CHECK(parse({{"uid", "p01"}, {"avatar_start", "1,2"}}).error ==
        "avatar_start '1,2' is not valid: use a spawn point's name or x,y,yaw in metres and radians");

  // A scenario without spawns or without a robot says so.
  std::string error;
  const auto bare = parse_scenario_facts("task: {steps: [{type: reach}]}\n", "bare", "bare.yaml", error);
  REQUIRE(bare);
  const std::vector<ScenarioFacts> bare_facts = {*bare};
  CHECK(parse_start_request({{"uid", "p01"}, {"avatar_start", "dock"}}, {"bare"}, bare_facts).error ==
        "avatar_start 'dock' is not a spawn point of bare (known: none; or give x,y,yaw)");
  CHECK(parse_start_request({{"uid", "p01"}, {"robot_goal", "1,2,0"}}, {"bare"}, bare_facts).error ==
        "robot_goal is not valid here: scenario bare has no robot");
  CHECK(parse_start_request({{"uid", "p01"}, {"robot_control", "external"}}, {"bare"}, bare_facts).error ==
        "robot_control is not valid here: scenario bare has no robot");
  CHECK(parse_start_request({{"uid", "p01"}, {"avatar_start", "1,2,0"}}, {"bare"}, bare_facts).request);
}

TEST_CASE("robot_control on a scenario with a robot is a mode, not a spawn point") {
  const std::vector<ScenarioFacts> facts = {depot_facts()};
  for (const char* value : {"builtin", "external"}) {
    const StartParse parsed = parse_start_request({{"uid", "p01"}, {"robot_control", value}}, {"depot"}, facts);
    INFO(parsed.error);
    REQUIRE(parsed.request);
    CHECK(parsed.request->overrides == std::vector<std::pair<std::string, std::string>>{{"robot_control", value}});
  }
}

TEST_CASE("condition is interactive by default, or video, and a video link sets no world of its own") {
  CHECK(parse_with("uid", "p01").request->condition == "interactive");
  CHECK(parse_with("condition", "interactive").request->condition == "interactive");
  CHECK(parse_with("condition", "video").request->condition == "video");
  for (const char* bad : {"Video", "", "watch", "video "}) {
    CAPTURE(bad);
    const StartParse parsed = parse_with("condition", bad);
    REQUIRE_FALSE(parsed.request);
    CHECK(parsed.error.find("use interactive or video") != std::string::npos);
  }
  // The recording's seed, poses, crowd, robot and view are the walker's: a video link may not set them.
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"seed", "7"}, {"crowd", "3"}, {"camera", "first_person"}, {"avatar_start", "1,2,0"}, {"robot_control", "builtin"}}) {
    CAPTURE(name);
    const StartParse parsed =
        parse_start_request(QueryParams{{"uid", "p01"}, {"scenario", "lab"}, {"condition", "video"}, {name, value}}, kScenarios);
    REQUIRE_FALSE(parsed.request);
    CHECK(parsed.error == name + " is not valid with condition=video: the watcher is shown the recorded session as it was");
  }
  // Codes are the watcher's own.
  const StartParse coded =
      parse_start_request(QueryParams{{"uid", "p01"}, {"condition", "video"}, {"t1", "VID-1"}}, kScenarios);
  REQUIRE(coded.request);
  CHECK(coded.request->code_success == "VID-1");
}

TEST_CASE("yoke_uid is an identifier, and only for a video link") {
  const StartParse pinned =
      parse_start_request(QueryParams{{"uid", "b1"}, {"condition", "video"}, {"yoke_uid", "a-7"}}, kScenarios);
  REQUIRE(pinned.request);
  CHECK(pinned.request->yoke_uid == "a-7");
  const StartParse alone = parse_with("yoke_uid", "a-7");
  REQUIRE_FALSE(alone.request);
  CHECK(alone.error == "yoke_uid is for condition=video links only");
  const StartParse bad =
      parse_start_request(QueryParams{{"uid", "b1"}, {"condition", "video"}, {"yoke_uid", "a/7"}}, kScenarios);
  REQUIRE_FALSE(bad.request);
  CHECK(bad.error.find("yoke_uid 'a/7' is not valid") != std::string::npos);
}
