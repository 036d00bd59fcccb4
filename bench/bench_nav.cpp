// SPDX-License-Identifier: GPL-2.0-or-later
// bench_nav: what the robot's stack costs and how well it navigates, over the seeded warehouse trials
// (tests/nav/warehouse_trials.hpp: north_middle <-> dock among 15 pedestrians).
//   Table 1: per-call cost of each stage (lidar, localization, costmaps, global plan, local plan), how often
//            it runs per simulated second, and its share of one core; then the whole stack's share.
//   Table 2: the navigation metrics of the trials (success, time to goal, path length, closest approach,
//            time in the intimate and personal zones, collisions).
// Usage: bench_nav [--trials N] [--first-seed S]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "warehouse_trials.hpp"

namespace bench = rfbsim::bench;
namespace sim = rfbsim::sim;
namespace test = rfbsim::test;

namespace {

struct Options {
  int trials = test::kWarehouseTrials;
  int first_seed = 1;
};

Options parse(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((arg == "--trials" || arg == "--first-seed") && i + 1 < argc) {
      const int value = bench::parse_int(argv[++i], arg == "--trials" ? 1 : 0, 100000, arg);
      (arg == "--trials" ? options.trials : options.first_seed) = value;
    } else {
      throw std::invalid_argument("unknown argument '" + arg + "' (usage: bench_nav [--trials N] [--first-seed S])");
    }
  }
  return options;
}

constexpr int kStages = static_cast<int>(sim::NavStage::Count);
const char* const kStageNames[kStages] = {"lidar (360 beams)", "localization (AMCL)", "costmaps (local + global)",
                                          "global plan (A*)", "local plan (DWA)"};

/// One trial, stepped here so that each tick's stage costs become samples.
struct TrialResult {
  test::NavRun run;
  double simulated = 0.0;  // s
};

TrialResult run_trial(std::uint64_t seed, std::vector<std::vector<double>>& samples, double& stack_seconds) {
  sim::ScenarioOverrides overrides;
  overrides.avatar_start = "office";
  overrides.robot_start = seed % 2 == 0 ? "north_middle" : "dock";
  overrides.robot_goal = seed % 2 == 0 ? "dock" : "north_middle";
  auto simulation = test::make_mission_simulation("warehouse", seed, overrides);
  const sim::RobotStack& stack = *simulation->robot_stack();
  test::NavWatch watch;
  sim::StageTimes last = stack.stage_times();
  const double dt = simulation->params().dt;
  while (simulation->world().time < test::kWarehouseTrialLimit) {
    simulation->step();
    const sim::StageTimes& now = stack.stage_times();
    for (std::size_t s = 0; s < kStages; ++s) {
      // A stage runs at most once per tick: the difference is one call.
      if (now.runs[s] != last.runs[s]) samples[s].push_back((now.seconds[s] - last.seconds[s]) * 1e3);
      stack_seconds += now.seconds[s] - last.seconds[s];
    }
    last = now;
    if (watch.observe(simulation->world(), dt)) break;
  }
  return {watch.result(), simulation->world().time};
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    std::printf("bench_nav: CPU %s; load average %s at start; %d warehouse trials from seed %d\n\n",
                bench::cpu_description().c_str(), bench::load_average().c_str(), options.trials,
                options.first_seed);
    std::vector<std::vector<double>> samples(kStages);
    double stack_seconds = 0.0;
    double simulated = 0.0;
    std::vector<test::NavRun> runs;
    for (int i = 0; i < options.trials; ++i) {
      const auto seed = static_cast<std::uint64_t>(options.first_seed + i);
      TrialResult trial = run_trial(seed, samples, stack_seconds);
      simulated += trial.simulated;
      runs.push_back(std::move(trial.run));
      std::fprintf(stderr, "trial %d/%d: %s\n", i + 1, options.trials,
                   runs.back().arrived ? "arrived" : runs.back().last_detail.c_str());
    }

    // Table 1: cost per stage.
    bench::Table cost({"stage", "calls per sim s", "p50 ms", "p90 ms", "mean ms", "max ms", "% of one core"}, 1);
    for (std::size_t s = 0; s < kStages; ++s) {
      const bench::Summary summary = bench::summarize(samples[s]);
      const double rate = static_cast<double>(summary.n) / simulated;
      cost.add_row({kStageNames[s], bench::fixed(rate, 1), bench::fixed(summary.p50, 3), bench::fixed(summary.p90, 3),
                    bench::fixed(summary.mean, 3), bench::fixed(summary.max, 2),
                    bench::fixed(summary.mean * rate / 10.0, 2)});
    }
    cost.add_row({"whole stack", "", "", "", "", "", bench::fixed(stack_seconds / simulated * 100.0, 2)});
    cost.print();

    // Table 2: navigation metrics.
    int arrived = 0, fault_free = 0, robot_on_person = 0, person_on_robot = 0;
    std::vector<double> times, lengths, closest, approach, intimate, personal;
    for (const auto& run : runs) {
      if (run.arrived) {
        ++arrived;
        times.push_back(run.end_time);
        lengths.push_back(run.metrics.path_length);
      }
      if (run.metrics.robot_on_person == 0) ++fault_free;
      robot_on_person += run.metrics.robot_on_person;
      person_on_robot += run.metrics.person_on_robot;
      closest.push_back(run.metrics.min_person_distance);
      approach.push_back(std::min(run.metrics.min_distance_robot_approaching, 10.0));
      intimate.push_back(run.metrics.intimate_fraction * 100.0);
      personal.push_back(run.metrics.personal_fraction * 100.0);
    }
    const auto n = static_cast<double>(runs.size());
    const auto t = bench::summarize(times), l = bench::summarize(lengths), c = bench::summarize(closest);
    const auto a = bench::summarize(approach);
    const auto in_intimate = bench::summarize(intimate), in_personal = bench::summarize(personal);
    std::printf("\n");
    bench::Table nav({"metric", "value"}, 1);
    nav.add_row({"success (arrived within 300 s)", bench::fixed(arrived / n * 100.0, 1) + " % (" +
                                                       std::to_string(arrived) + "/" + std::to_string(runs.size()) + ")"});
    nav.add_row({"trials without a robot-at-fault collision", bench::fixed(fault_free / n * 100.0, 1) + " %"});
    nav.add_row({"collisions robot-on-person / person-on-robot", std::to_string(robot_on_person) + " / " +
                                                                     std::to_string(person_on_robot)});
    nav.add_row({"time to goal, s (median / mean)", bench::fixed(t.p50, 1) + " / " + bench::fixed(t.mean, 1)});
    nav.add_row({"path length, m (median / mean)", bench::fixed(l.p50, 1) + " / " + bench::fixed(l.mean, 1)});
    nav.add_row({"min distance to people, m (median / mean / lowest)",
                 bench::fixed(c.p50, 2) + " / " + bench::fixed(c.mean, 2) + " / " +
                     bench::fixed(*std::min_element(closest.begin(), closest.end()), 2)});
    nav.add_row({"closest the robot itself came, m (median / mean / lowest)",
                 bench::fixed(a.p50, 2) + " / " + bench::fixed(a.mean, 2) + " / " +
                     bench::fixed(*std::min_element(approach.begin(), approach.end()), 2)});
    nav.add_row({"time in intimate zone (< 0.45 m), % (median / mean)",
                 bench::fixed(in_intimate.p50, 2) + " / " + bench::fixed(in_intimate.mean, 2)});
    nav.add_row({"time in personal zone (< 1.2 m), % (median / mean)",
                 bench::fixed(in_personal.p50, 2) + " / " + bench::fixed(in_personal.mean, 2)});
    nav.print();
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_nav: %s\n", error.what());
    return 2;
  }
}
