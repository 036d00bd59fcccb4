// SPDX-License-Identifier: GPL-2.0-or-later
// Fifty seeded warehouse trials with 15 pedestrians: the robot reaches its goal in at least 90 % of them,
// and in at least 95 % it never drives into anyone (REFERENCE.md: a collision is a gap under 2 cm; the
// robot is at fault when it closed the gap faster than the person).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "warehouse_trials.hpp"

namespace {

// Under AddressSanitizer a trial runs about 20 times slower: the sanitizer build (scripts/test.sh --sanitize)
// is there for memory errors, so it runs the first ten trials, with the same thresholds as shares.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kTrials = 10;
#else
constexpr int kTrials = rfbsim::test::kWarehouseTrials;
#endif

}  // namespace

TEST_CASE("nav: 50 warehouse trials among 15 pedestrians", "[nav][warehouse]") {
  int arrived = 0;
  int without_fault = 0;
  double closest_sum = 0.0;
  double approach_sum = 0.0;
  const char* only = std::getenv("RFBSIM_TRIAL");  // debugging: run one trial
  for (int seed = 1; seed <= kTrials; ++seed) {
    if (only && std::atoi(only) != seed) continue;
    const auto run = rfbsim::test::warehouse_trial(static_cast<std::uint64_t>(seed));
    if (run.arrived) ++arrived;
    if (run.metrics.robot_on_person == 0) ++without_fault;
    closest_sum += run.metrics.min_person_distance;
    approach_sum += std::min(run.metrics.min_distance_robot_approaching, 10.0);
    std::printf("trial %2d: %-8s %6.1f s, %5.1f m, closest %.2f m, worst estimate error %.2f m, robot-on-person %d, "
                "person-on-robot %d%s%s\n",
                seed, run.arrived ? "arrived" : (run.failed ? "failed" : "timeout"), run.end_time,
                run.metrics.path_length, run.metrics.min_person_distance, run.max_estimate_error, run.metrics.robot_on_person,
                run.metrics.person_on_robot, run.arrived ? "" : ": ", run.arrived ? "" : run.last_detail.c_str());
    CHECK_FALSE(run.hit_wall);
  }
  const double trials = only ? 1.0 : kTrials;
  std::printf("arrived %d/%d, no robot-at-fault collision %d/%d, mean closest approach %.2f m (robot closing in: "
              "%.2f m)\n", arrived, kTrials, without_fault, kTrials, closest_sum / trials, approach_sum / trials);
  if (only) return;
  CHECK(arrived >= (kTrials * 90 + 99) / 100);        // 90 %: 45 of 50
  CHECK(without_fault >= (kTrials * 95 + 99) / 100);  // 95 %: 48 of 50 (47.5 rounded up)
}
