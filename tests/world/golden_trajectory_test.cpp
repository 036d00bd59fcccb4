// SPDX-License-Identifier: GPL-2.0-or-later
// The golden trajectory: a fixed scenario, seed and key script give a digest of every agent's pose at every
// tick that is checked in here, so that any change of behaviour between commits (the crowd, the physics, the
// robot's stack, the avatar) shows up as a failing test instead of passing unnoticed. When a change is meant
// to alter behaviour, update the digest with the reason in the commit message; the failure prints the new one.
//
// Poses are quantised (0.1 mm, 0.1 mrad) before hashing, so that the digest names behaviour, not the last bit
// of a double. On x86-64 without -march flags the compiler contracts nothing into FMA, so optimisation levels
// agree: RelWithDebInfo (CI), Release (-O3) and the Debug ASan/UBSan build of scripts/test.sh --sanitize gave
// this one digest (2026-11-26, GCC 12). If a build type ever disagrees, give it its own digest here rather
// than loosening the check.
#include <catch2/catch.hpp>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <string>

#include "scripted_run.hpp"

using rfbsim::test::ScriptedKey;

namespace {

// Out of the dock towards the robot's route, a turn, a run, a stop: 30 s at 60 Hz with the robot on its mission.
const std::vector<ScriptedKey> kGoldenScript = {
    {0, 'w', true},     {240, 'd', true},  {300, 'd', false}, {600, 'W', true},  {660, 'w', false},
    {700, 'a', true},   {790, 'a', false}, {800, 'w', true},  {1200, 'W', false}, {1500, 'w', false},
};
constexpr std::uint64_t kGoldenTicks = 1800;
constexpr std::uint64_t kSeed = 11;

// The digest of the run above. Update it only for a deliberate change of behaviour, saying why in the commit.
constexpr const char* kGoldenWarehouse = "4eed71523489cb7a";

// FNV-1a, 64 bits, over the quantised poses in tick order.
class Fnv1a {
 public:
  void add(std::int64_t value) {
    for (int byte = 0; byte < 8; ++byte) {
      hash_ ^= static_cast<std::uint64_t>(value >> (8 * byte)) & 0xffu;
      hash_ *= 0x100000001b3ull;
    }
  }
  [[nodiscard]] std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016" PRIx64, hash_);
    return text;
  }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

std::string trajectory_digest(const std::vector<std::vector<double>>& trace) {
  Fnv1a digest;
  for (const auto& poses : trace) {
    for (const double value : poses) digest.add(std::llround(value * 1e4));
  }
  return digest.hex();
}

}  // namespace

TEST_CASE("the warehouse with seed 11 and the golden key script gives the checked-in trajectory digest") {
  auto simulation = rfbsim::test::make_scenario_simulation("warehouse", kSeed, {}, true);
  const auto trace = rfbsim::test::run_scripted(*simulation, kGoldenScript, kGoldenTicks);
  REQUIRE(trace.size() == kGoldenTicks);
  // The run did something worth pinning: the avatar walked and the robot drove.
  CHECK(simulation->world().avatar.distance_walked > 5.0);
  const auto& robot_start = trace.front();
  const auto& robot_end = trace.back();
  const std::size_t robot = robot_end.size() - 3;
  CHECK(std::hypot(robot_end[robot] - robot_start[robot], robot_end[robot + 1] - robot_start[robot + 1]) > 1.0);
  const std::string digest = trajectory_digest(trace);
  INFO("trajectory digest now " << digest << "; if the change of behaviour is deliberate, put it in kGoldenWarehouse "
                                   "(tests/world/golden_trajectory_test.cpp) and say why in the commit");
  CHECK(digest == kGoldenWarehouse);
}
