// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: scenario files (the input is the scenario's YAML, next to a small valid map room.yaml).
// Invariants: load_scenario throws nothing but ScenarioError, whatever the text (yaml-cpp's own exceptions,
// std::out_of_range and the like escaping would be bugs); a loaded scenario has a map, a name, spawns on
// the map and can build its initial world; the YAML depth estimate is never below yaml-cpp's.
#include <string>

#include "fuzz_check.hpp"
#include "scenario/scenario.hpp"
#include "scratch_files.hpp"
#include "yaml_depth_check.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::sim;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);
  rfbsim::fuzz::check_yaml_depth_estimate(text);
  const auto file = rfbsim::fuzz::ScratchFiles::get().write("scenario.yaml", text);
  Scenario scenario;
  try {
    scenario = load_scenario(file);
  } catch (const ScenarioError& e) {
    check(std::string(e.what()).find(file.string()) != std::string::npos, "error does not name the file");
    return 0;
  }
  check(!scenario.name.empty(), "loaded scenario without a name");
  check(scenario.map.width > 0 && scenario.map.height > 0, "loaded scenario without a map");
  for (const SpawnPoint& spawn : scenario.spawns) {
    check(scenario.map.contains(spawn.pose.x, spawn.pose.y), "spawn point off the map");
  }
  (void)make_world(scenario);
  return 0;
}
