// SPDX-License-Identifier: GPL-2.0-or-later
// Determinism: the same scenario, seed and key script give the same trajectories bit for bit (what makes
// replay and video export exact); another seed gives another crowd.
#include <catch2/catch.hpp>

#include <cstring>

#include "scripted_run.hpp"

using rfbsim::test::ScriptedKey;

namespace {

// Walk out of the dock, turn left for a second, walk on, stop, look up: 20 s at 60 Hz.
const std::vector<ScriptedKey> kScript = {
    {0, 'w', true},    {180, 'a', true}, {240, 'a', false}, {600, 'W', true}, {620, 'w', false},
    {700, 'd', true},  {760, 'd', false}, {900, 'W', false}, {950, 0xff52, true}, {1000, 0xff52, false},
};
constexpr std::uint64_t kTicks = 1200;

bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("the warehouse run twice with one seed and one key script matches bit for bit at every tick") {
  auto first = rfbsim::test::make_scenario_simulation("warehouse", 11, {}, true);
  auto second = rfbsim::test::make_scenario_simulation("warehouse", 11, {}, true);
  const auto a = rfbsim::test::run_scripted(*first, kScript, kTicks);
  const auto b = rfbsim::test::run_scripted(*second, kScript, kTicks);
  REQUIRE(a.size() == kTicks);
  REQUIRE(b.size() == kTicks);
  CHECK(a.front().size() == 3 * (1 + 15 + 1));  // avatar, 15 people, robot
  std::uint64_t first_difference = kTicks;
  for (std::uint64_t tick = 0; tick < kTicks; ++tick) {
    if (!bitwise_equal(a[tick], b[tick])) {
      first_difference = tick;
      break;
    }
  }
  CHECK(first_difference == kTicks);
  // The run did something: the avatar walked (it may bump into people and racks) and the crowd moved.
  CHECK(first->world().avatar.distance_walked > 3.0);
  double crowd_motion = 0.0;
  for (std::size_t i = 3; i + 3 < a.back().size(); i += 3) crowd_motion += std::abs(a.back()[i] - a.front()[i]);
  CHECK(crowd_motion > 10.0);
  // Contacts and events are part of the state too.
  CHECK(first->world().tick == second->world().tick);
}

TEST_CASE("another seed gives another crowd") {
  auto one = rfbsim::test::make_scenario_simulation("warehouse", 11, {}, true);
  auto other = rfbsim::test::make_scenario_simulation("warehouse", 12, {}, true);
  const auto a = rfbsim::test::run_scripted(*one, {}, 60);
  const auto b = rfbsim::test::run_scripted(*other, {}, 60);
  // The avatar starts where the scenario says whatever the seed; the people do not.
  CHECK(a.front()[0] == Approx(b.front()[0]).margin(1e-3));
  CHECK(a.front()[1] == Approx(b.front()[1]).margin(1e-3));
  int people_elsewhere = 0;
  for (std::size_t i = 3; i + 3 < a.back().size(); i += 3) {
    if (std::hypot(a.back()[i] - b.back()[i], a.back()[i + 1] - b.back()[i + 1]) > 0.5) ++people_elsewhere;
  }
  CHECK(people_elsewhere >= 10);
}
