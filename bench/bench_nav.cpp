// SPDX-License-Identifier: GPL-2.0-or-later
// bench_nav: what the robot's stack costs and how well it navigates, over the seeded warehouse trials
// (tests/support/warehouse_trials.hpp: north_middle <-> dock among 15 pedestrians).
//   Table 1: per-call cost of each stage (lidar, localization, costmaps, global plan, local plan), how often
//            it runs per simulated second, and its share of one core; then the whole stack's share.
//   Table 2: the navigation metrics of the trials (success, time to goal, path length, closest approach,
//            time in the intimate and personal zones, collisions) and the social-navigation metrics of
//            simulator/robot/social_metrics.hpp (the robot's share of personal-space intrusions, its closest
//            approach while moving toward someone, time to collision, path irregularity, time stopped).
// Usage: bench_nav [--trials N] [--first-seed S] [--nav FILE] [--before | --compare]
//   --nav FILE  a YAML mapping laid out as a scenario's robot.nav (docs/scenarios.md), applied over the
//               warehouse scenario's robot parameters: try settings without editing the scenario.
//   --before    the trials with the settings from before the robot kept its distance (issue 19).
//   --compare   both: table 2 gets a column for the old settings and one for today's.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "robot/social_metrics.hpp"
#include "scenario/robot_params_yaml.hpp"
#include "warehouse_trials.hpp"

namespace bench = rfbsim::bench;
namespace sim = rfbsim::sim;
namespace test = rfbsim::test;

namespace {

struct Options {
  int trials = test::kWarehouseTrials;
  int first_seed = 1;
  std::string nav_file;
  bool before = false;
  bool compare = false;
};

Options parse(int argc, char** argv) {
  Options options;
  bench::CommandLine cli("bench_nav",
                         "The robot stack's cost per stage and the navigation metrics of the warehouse trials.");
  cli.number("--trials", options.trials, 1, 100000, "warehouse trials");
  cli.number("--first-seed", options.first_seed, 0, 100000, "the first trial's seed");
  cli.app().add_option("--nav", options.nav_file, "navigation settings (YAML) instead of the scenario's")
      ->type_name("FILE")->check(bench::non_empty());
  cli.flag("--before", options.before, "the settings from before issue 19");
  cli.flag("--compare", options.compare, "before issue 19 and now, side by side");
  cli.parse(argc, argv);
  if (options.before && options.compare) throw std::invalid_argument("--before or --compare, not both");
  return options;
}

/// The settings the issue-19 tuning changed, back at their old values (the defaults up to then), so that
/// --before and --compare show what the tuning bought. Everything else stays at today's defaults.
void restore_previous_defaults(sim::RobotParams& p) {
  sim::ProxemicLayerParams old_proxemic;
  old_proxemic.amplitude = 77.0;
  old_proxemic.covariance = 0.25;
  old_proxemic.cutoff = 10.0;
  old_proxemic.factor = 5.0;
  p.global_costmap.proxemic = old_proxemic;
  p.local_costmap.proxemic = old_proxemic;
  p.dwa.people_clearance = 0.1;
  p.dwa.people_horizon = 1.0;
  p.dwa.people_personal_clearance = 0.0;
}

/// The warehouse scenario's robot parameters, with the old defaults when `before`, then `nav_file`'s keys.
sim::RobotParams trial_params(bool before, const std::string& nav_file) {
  sim::Scenario scenario = sim::load_scenario(std::string(RFBSIM_SCENARIO_DIR) + "/warehouse.yaml");
  sim::RobotParams params = scenario.robot.params;
  if (before) restore_previous_defaults(params);
  if (!nav_file.empty()) sim::parse_robot_params(sim::read_yaml_file(nav_file), params);
  return params;
}

constexpr int kStages = static_cast<int>(sim::NavStage::Count);
const char* const kStageNames[kStages] = {"lidar (360 beams)", "localization (AMCL)", "costmaps (local + global)",
                                          "global plan (A*)", "local plan (DWA)"};

/// One trial, stepped here so that each tick's stage costs become samples and each tick's poses a sample
/// of the social metrics.
struct TrialResult {
  test::NavRun run;
  sim::SocialMetrics social;
  double simulated = 0.0;  // s
};

TrialResult run_trial(std::uint64_t seed, const sim::RobotParams& params, std::vector<std::vector<double>>& samples,
                      double& stack_seconds) {
  sim::ScenarioOverrides overrides;
  overrides.avatar_start = "office";
  overrides.robot_start = seed % 2 == 0 ? "north_middle" : "dock";
  overrides.robot_goal = seed % 2 == 0 ? "dock" : "north_middle";
  auto simulation = test::make_mission_simulation("warehouse", seed, overrides, &params);
  const sim::RobotStack& stack = *simulation->robot_stack();
  test::NavWatch watch;
  std::vector<sim::SocialSample> series{sim::social_sample(simulation->world())};
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
    series.push_back(sim::social_sample(simulation->world()));
    if (watch.observe(simulation->world(), dt)) break;
  }
  sim::SocialMetricsParams social;
  social.robot_radius = simulation->world().robot->radius;
  if (const auto& goal = simulation->world().robot->nav.goal) social.goal = Eigen::Vector2d(goal->x, goal->y);
  return {watch.result(), sim::social_metrics(series, social), simulation->world().time};
}

/// The trials of one parameter set, with the stage costs they sampled.
struct TrialSet {
  std::vector<TrialResult> trials;
  std::vector<std::vector<double>> samples = std::vector<std::vector<double>>(kStages);
  double stack_seconds = 0.0;
  double simulated = 0.0;
};

TrialSet run_trials(const Options& options, const sim::RobotParams& params, const char* label) {
  TrialSet set;
  for (int i = 0; i < options.trials; ++i) {
    const auto seed = static_cast<std::uint64_t>(options.first_seed + i);
    set.trials.push_back(run_trial(seed, params, set.samples, set.stack_seconds));
    set.simulated += set.trials.back().simulated;
    const test::NavRun& run = set.trials.back().run;
    const sim::SocialMetrics& social = set.trials.back().social;
    std::fprintf(stderr, "%strial %d/%d: %s %.1f s; robot's own approach %.2f m, robot-caused intrusions %d/%d, "
                 "stopped %.1f s\n", label, i + 1, options.trials, run.arrived ? "arrived" : run.last_detail.c_str(),
                 run.end_time, run.metrics.min_distance_robot_approaching, social.robot_personal_intrusions,
                 social.personal_intrusions, social.time_stopped);
  }
  return set;
}

void print_costs(const TrialSet& set) {
  bench::Table cost({"stage", "calls per sim s", "p50 ms", "p90 ms", "mean ms", "max ms", "% of one core"}, 1);
  for (std::size_t s = 0; s < kStages; ++s) {
    const bench::Summary summary = bench::summarize(set.samples[s]);
    const double rate = static_cast<double>(summary.n) / set.simulated;
    cost.add_row({kStageNames[s], bench::fixed(rate, 1), bench::fixed(summary.p50, 3), bench::fixed(summary.p90, 3),
                  bench::fixed(summary.mean, 3), bench::fixed(summary.max, 2),
                  bench::fixed(summary.mean * rate / 10.0, 2)});
  }
  cost.add_row({"whole stack", "", "", "", "", "", bench::fixed(set.stack_seconds / set.simulated * 100.0, 2)});
  cost.print();
}

double lowest(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end());
}

std::string three(const bench::Summary& s, double low, int decimals = 2) {
  return bench::fixed(s.p50, decimals) + " / " + bench::fixed(s.mean, decimals) + " / " + bench::fixed(low, decimals);
}

/// Table 2's rows for one set of trials: {metric, value}.
std::vector<std::pair<std::string, std::string>> nav_rows(const TrialSet& set) {
  // Distances with nobody around (and times with no collision course) are capped so that they stay
  // printable; in the warehouse someone is always around.
  constexpr double kFar = 10.0, kLong = 60.0;
  int arrived = 0, fault_free = 0, robot_on_person = 0, person_on_robot = 0;
  int intrusions = 0, robot_intrusions = 0, robot_intimate = 0, own_approach_intimate = 0;
  std::vector<double> times, lengths, closest, approach, intimate, personal;
  std::vector<double> toward, gap, ttc, ttc_toward, irregularity, stopped, robot_intrusions_per_trial;
  for (const TrialResult& trial : set.trials) {
    const test::NavRun& run = trial.run;
    const sim::SocialMetrics& s = trial.social;
    if (run.arrived) {
      ++arrived;
      times.push_back(run.end_time);
      lengths.push_back(run.metrics.path_length);
    }
    if (run.metrics.robot_on_person == 0) ++fault_free;
    robot_on_person += run.metrics.robot_on_person;
    person_on_robot += run.metrics.person_on_robot;
    closest.push_back(run.metrics.min_person_distance);
    approach.push_back(std::min(run.metrics.min_distance_robot_approaching, kFar));
    if (run.metrics.min_distance_robot_approaching < 0.45) ++own_approach_intimate;
    intimate.push_back(run.metrics.intimate_fraction * 100.0);
    personal.push_back(run.metrics.personal_fraction * 100.0);
    intrusions += s.personal_intrusions;
    robot_intrusions += s.robot_personal_intrusions;
    robot_intimate += s.robot_intimate_intrusions;
    robot_intrusions_per_trial.push_back(s.robot_personal_intrusions);
    toward.push_back(std::min(s.min_distance_robot_approaching, kFar));
    gap.push_back(std::min(s.min_gap, kFar));
    ttc.push_back(std::min(s.min_ttc, kLong));
    ttc_toward.push_back(std::min(s.min_ttc_robot_approaching, kLong));
    irregularity.push_back(s.path_irregularity_per_m);
    stopped.push_back(s.time_stopped);
  }
  const auto n = static_cast<double>(set.trials.size());
  const std::string count = std::to_string(set.trials.size());
  const auto t = bench::summarize(times), l = bench::summarize(lengths), c = bench::summarize(closest);
  const auto a = bench::summarize(approach);
  const auto in_intimate = bench::summarize(intimate), in_personal = bench::summarize(personal);
  const auto tw = bench::summarize(toward), g = bench::summarize(gap), tt = bench::summarize(ttc);
  const auto ttw = bench::summarize(ttc_toward), pi = bench::summarize(irregularity), st = bench::summarize(stopped);
  const auto ri = bench::summarize(robot_intrusions_per_trial);
  const double share = intrusions > 0 ? 100.0 * robot_intrusions / intrusions : 0.0;
  return {
      {"success (arrived within 300 s)",
       bench::fixed(arrived / n * 100.0, 1) + " % (" + std::to_string(arrived) + "/" + count + ")"},
      {"trials without a robot-at-fault collision", bench::fixed(fault_free / n * 100.0, 1) + " %"},
      {"collisions robot-on-person / person-on-robot",
       std::to_string(robot_on_person) + " / " + std::to_string(person_on_robot)},
      {"time to goal, s (median / mean)", bench::fixed(t.p50, 1) + " / " + bench::fixed(t.mean, 1)},
      {"path length, m (median / mean)", bench::fixed(l.p50, 1) + " / " + bench::fixed(l.mean, 1)},
      {"min distance to people, m (median / mean / lowest)", three(c, lowest(closest))},
      {"closest the robot itself came, m (median / mean / lowest)", three(a, lowest(approach))},
      {"trials where the robot itself came within 0.45 m, %",
       bench::fixed(own_approach_intimate / n * 100.0, 1) + " % (" + std::to_string(own_approach_intimate) + "/" +
           count + ")"},
      {"time in intimate zone (< 0.45 m), % (median / mean)",
       bench::fixed(in_intimate.p50, 2) + " / " + bench::fixed(in_intimate.mean, 2)},
      {"time in personal zone (< 1.2 m), % (median / mean)",
       bench::fixed(in_personal.p50, 2) + " / " + bench::fixed(in_personal.mean, 2)},
      {"personal-space intrusions (< 1.2 m): robot-caused / all (share)",
       std::to_string(robot_intrusions) + " / " + std::to_string(intrusions) + " (" + bench::fixed(share, 1) + " %)"},
      {"robot-caused personal-space intrusions per trial (median / mean)",
       bench::fixed(ri.p50, 1) + " / " + bench::fixed(ri.mean, 2)},
      {"robot-caused intimate-space intrusions (< 0.45 m), all trials", std::to_string(robot_intimate)},
      {"min distance while moving toward the person, m (median / mean / lowest)", three(tw, lowest(toward))},
      {"min surface gap to people, m (median / mean / lowest)", three(g, lowest(gap))},
      {"min time to collision, s (median / lowest)", bench::fixed(tt.p50, 2) + " / " + bench::fixed(lowest(ttc), 2)},
      {"min TTC while moving toward them, s (median / lowest)",
       bench::fixed(ttw.p50, 2) + " / " + bench::fixed(lowest(ttc_toward), 2)},
      {"path irregularity, rad/m (median / mean)", bench::fixed(pi.p50, 3) + " / " + bench::fixed(pi.mean, 3)},
      {"time stopped, s (median / mean / max)",
       bench::fixed(st.p50, 1) + " / " + bench::fixed(st.mean, 1) + " / " + bench::fixed(st.max, 1)},
  };
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    std::printf("bench_nav: CPU %s; load average %s at start; %d warehouse trials from seed %d%s%s%s\n\n",
                bench::cpu_description().c_str(), bench::load_average().c_str(), options.trials,
                options.first_seed, options.before ? "; settings from before issue 19" : "",
                options.compare ? "; before issue 19 and now" : "",
                options.nav_file.empty() ? "" : ("; --nav " + options.nav_file).c_str());
    const TrialSet now =
        run_trials(options, trial_params(options.before, options.nav_file), options.compare ? "now: " : "");
    std::optional<TrialSet> before;
    if (options.compare) before = run_trials(options, trial_params(true, options.nav_file), "before: ");

    // Table 1: cost per stage (of the settings asked for; of today's with --compare).
    print_costs(now);

    // Table 2: navigation and social-navigation metrics.
    std::printf("\n");
    const auto rows = nav_rows(now);
    if (before) {
      const auto old_rows = nav_rows(*before);
      bench::Table nav({"metric", "before (issue 4 settings)", "now"}, 1);
      for (std::size_t i = 0; i < rows.size(); ++i) nav.add_row({rows[i].first, old_rows[i].second, rows[i].second});
      nav.print();
    } else {
      bench::Table nav({"metric", "value"}, 1);
      for (const auto& [metric, value] : rows) nav.add_row({metric, value});
      nav.print();
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_nav: %s\n", error.what());
    return 2;
  }
}
