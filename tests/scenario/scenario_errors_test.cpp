// SPDX-License-Identifier: GPL-2.0-or-later
// Broken scenario files: each mistake is reported with the file, the key and what was expected.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <fstream>

#include "scenario/scenario.hpp"

using namespace rfbsim::sim;

namespace {

// A scratch folder with a valid 4 x 4 m map (0.1 m cells, a wall all round) and scenario text to try.
class ScratchScenario {
 public:
  ScratchScenario() {
    static int counter = 0;
    dir_ = std::filesystem::temp_directory_path() /
           ("rfbsim_scenario_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(dir_);
    std::ofstream pgm(dir_ / "room.pgm", std::ios::binary);
    pgm << "P5\n40 40\n255\n";
    for (int row = 0; row < 40; ++row) {
      for (int col = 0; col < 40; ++col) {
        const bool wall = row < 2 || row >= 38 || col < 2 || col >= 38;
        pgm.put(static_cast<char>(wall ? 0 : 254));
      }
    }
    pgm.close();
    write("room.yaml",
          "image: room.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
          "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  }
  ~ScratchScenario() { std::filesystem::remove_all(dir_); }
  ScratchScenario(const ScratchScenario&) = delete;
  ScratchScenario& operator=(const ScratchScenario&) = delete;

  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  // The message of the ScenarioError that loading `text` as s.yaml throws ("" if none).
  std::string error_of(const std::string& text) const {
    write("s.yaml", text);
    try {
      (void)load_scenario(dir_ / "s.yaml");
    } catch (const ScenarioError& e) {
      return e.what();
    }
    return "";
  }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

const std::string kValid =
    "map: room.yaml\n"
    "spawns:\n  a: [1.0, 1.0, 0.0]\n  b: [3.0, 3.0, 0.0]\n"
    "avatar:\n  start: a\n";

}  // namespace

TEST_CASE("a minimal valid scenario loads") {
  ScratchScenario scratch;
  CHECK(scratch.error_of(kValid).empty());
  scratch.write("s.yaml", kValid);
  const Scenario s = load_scenario(scratch.dir() / "s.yaml");
  CHECK(s.name == "s");
  CHECK(s.map.width == 40);
  CHECK(s.avatar_start.x == 1.0);
  CHECK_FALSE(s.robot.present);
  CHECK(s.crowd.count == 0);
}

TEST_CASE("scenario mistakes name the file, the key and what was expected") {
  ScratchScenario scratch;
  struct Case {
    const char* what;
    std::string text;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"missing avatar", "map: room.yaml\n", {"s.yaml", "missing key 'avatar'"}},
      {"missing map", "avatar:\n  start: [1, 1]\n", {"s.yaml", "missing key 'map'"}},
      {"crowd count not a number", kValid + "crowd:\n  count: many\n  goals: [a, b]\n",
       {"s.yaml:", "key 'crowd.count'", "expected an integer 0..500", "'many'"}},
      {"wrong type for props", kValid + "props: 3\n", {"key 'props'", "expected a list"}},
      {"prop size too short", kValid + "props:\n  - kind: box\n    pose: [2, 2]\n    size: [1, 1]\n",
       {"key 'props[0].size'", "a list of 3"}},
      {"unknown prop kind", kValid + "props:\n  - kind: sofa\n    pose: [2, 2]\n    size: [1, 1, 1]\n",
       {"key 'props[0].kind'", "box, shelf or desk", "'sofa'"}},
      {"unknown spawn name", "map: room.yaml\nspawns:\n  a: [1.0, 1.0]\navatar:\n  start: door\n",
       {"key 'avatar.start'", "no spawn point 'door'", "known: a"}},
      {"misspelt key", kValid + "crwod:\n  count: 2\n", {"key 'crwod'", "unknown key"}},
      {"spawn inside a wall", "map: room.yaml\nspawns:\n  w: [0.05, 2.0]\navatar:\n  start: w\n",
       {"key 'spawns.w'", "inside or against a wall"}},
      {"start off the map", "map: room.yaml\navatar:\n  start: [9.0, 9.0]\n", {"s.yaml", "off the map"}},
      {"crowd without places", kValid + "crowd:\n  count: 3\n", {"key 'crowd'", "'routes' or 'goals'"}},
      {"colour unquoted", kValid + "landmarks:\n  - name: g\n    position: [2, 2]\n    color: 12\n",
       {"key 'landmarks[0].color'", "#rrggbb"}},
      {"mission type", kValid + "robot:\n  start: b\n  mission:\n    type: dance\n",
       {"key 'robot.mission.type'", "goto, patrol, wander or none"}},
      {"unknown robot.nav section", kValid + "robot:\n  start: b\n  nav:\n    dwaa: {max_vel_x: 1}\n",
       {"key 'robot.nav.dwaa'", "unknown key"}},
      {"unknown robot.nav key", kValid + "robot:\n  start: b\n  nav:\n    dwa: {max_vel: 1}\n",
       {"key 'robot.nav.dwa.max_vel'", "unknown key"}},
      {"robot.nav value out of range", kValid + "robot:\n  start: b\n  nav:\n    dwa: {max_vel_x: -1}\n",
       {"key 'robot.nav.dwa.max_vel_x'", "-1"}},
      {"robot.nav localization", kValid + "robot:\n  start: b\n  nav:\n    localization: gps\n",
       {"key 'robot.nav.localization'", "amcl or ground_truth"}},
      {"lidar ranges that cannot work", kValid + "robot:\n  start: b\n  nav:\n    lidar: {range_min: 5, range_max: 2}\n",
       {"key 'robot.nav'", "range_max"}},
      {"local inflation inside the robot", kValid + "robot:\n  start: b\n  nav:\n    local_costmap: {inflation_radius: 0.1}\n",
       {"key 'robot.nav'", "inflation_radius must be at least the robot's padded radius"}},
      {"DWA limits that cannot work", kValid + "robot:\n  start: b\n  nav:\n    dwa: {min_vel_x: 0.3, max_vel_x: 0.2}\n",
       {"key 'robot.nav'", "min_vel_x <= max_vel_x"}},
      {"DWA beyond the wheels", kValid + "robot:\n  start: b\n  nav:\n    dwa: {max_vel_x: 0.9}\n",
       {"key 'robot.nav'", "within drive's"}},
      {"AMCL particle bounds", kValid + "robot:\n  start: b\n  nav:\n    amcl: {min_particles: 900, max_particles: 800}\n",
       {"key 'robot.nav'", "min_particles"}},
      {"mission goal in a wall", kValid + "robot:\n  start: b\n  mission: {type: goto, goal: [0.05, 2.0]}\n",
       {"s.yaml", "robot.mission place", "inside or against a wall"}},
      {"malformed YAML", "map: [room.yaml\navatar: {start: a\n", {"s.yaml:", "not valid YAML"}},
      {"a list at the top", "- map\n", {"s.yaml", "expected a mapping"}},
      {"map file missing", "map: nowhere.yaml\navatar:\n  start: [1, 1]\n", {"s.yaml", "key 'map'", "nowhere.yaml"}},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const std::string message = scratch.error_of(c.text);
    INFO(message);
    REQUIRE_FALSE(message.empty());
    for (const auto& needle : c.needles) CHECK_THAT(message, Catch::Contains(needle));
  }
}

TEST_CASE("a map image that cannot be read is reported through the scenario's map key") {
  ScratchScenario scratch;
  scratch.write("room.pgm", "P5\n40 40\n255\nshort");  // truncated pixels
  const std::string message = scratch.error_of(kValid);
  INFO(message);
  CHECK_THAT(message, Catch::Contains("s.yaml") && Catch::Contains("key 'map'") && Catch::Contains("room.pgm"));
  scratch.write("room.pgm", "GIF89a garbage");
  CHECK_THAT(scratch.error_of(kValid), Catch::Contains("room.pgm"));
}

TEST_CASE("scenario text too deep or too large for yaml-cpp is refused with the limit, before parsing") {
  ScratchScenario scratch;
  const std::string deep = kValid + "props: " + std::string(100000, '[') + "\n";
  CHECK_THAT(scratch.error_of(deep), Catch::Contains("s.yaml: YAML nested more than 32 levels deep (line 7)"));
  std::string nested = kValid + "extra:\n";
  for (int level = 1; level <= 40; ++level) nested += std::string(static_cast<std::size_t>(2 * level), ' ') + "k:\n";
  CHECK_THAT(scratch.error_of(nested), Catch::Contains("s.yaml: YAML nested more than 32 levels deep"));
  CHECK_THAT(scratch.error_of(kValid + "# " + std::string(1'000'001, 'x') + "\n"),
             Catch::Contains("s.yaml: too large for a YAML file here (over 1000000 bytes)"));
}

TEST_CASE("no file is read when the scenario file itself is missing") {
  try {
    (void)load_scenario("/nonexistent/dir/s.yaml");
    FAIL("loaded a missing file");
  } catch (const ScenarioError& e) {
    CHECK_THAT(e.what(), Catch::Contains("/nonexistent/dir/s.yaml") && Catch::Contains("cannot open"));
  }
}

TEST_CASE("camera is third_person unless the file or an override says first_person, and nothing else") {
  ScratchScenario scratch;
  scratch.write("s.yaml", kValid);
  CHECK(load_scenario(scratch.dir() / "s.yaml").camera == CameraMode::kThirdPerson);
  scratch.write("s.yaml", kValid + "camera: first_person\n");
  Scenario first = load_scenario(scratch.dir() / "s.yaml");
  CHECK(first.camera == CameraMode::kFirstPerson);
  scratch.write("s.yaml", kValid + "camera: third_person\n");
  CHECK(load_scenario(scratch.dir() / "s.yaml").camera == CameraMode::kThirdPerson);

  // A bad value names the file, the key, what is allowed and what was given; so does a bad override.
  for (const char* bad : {"fisrt_person", "First_Person", "overhead"}) {
    INFO(bad);
    const std::string message = scratch.error_of(kValid + "camera: " + bad + "\n");
    CHECK_THAT(message, Catch::Contains("s.yaml") && Catch::Contains("key 'camera'") &&
                            Catch::Contains("'third_person' or 'first_person'"));
  }
  ScenarioOverrides to_third;
  to_third.camera = "third_person";
  apply_overrides(first, to_third);
  CHECK(first.camera == CameraMode::kThirdPerson);
  ScenarioOverrides bad;
  bad.camera = "overhead";
  try {
    apply_overrides(first, bad);
    FAIL("no error for --camera overhead");
  } catch (const ScenarioError& e) {
    CHECK_THAT(e.what(), Catch::Contains("--camera") && Catch::Contains("'overhead'"));
  }
}
