// SPDX-License-Identifier: GPL-2.0-or-later
// bench_cluster: a study cluster (scripts/run-cluster-demo.sh: sim_manager hosts behind HAProxy, with
// examples/minimal as the light session program) measured against issue 18's targets, and the balancer's own hop.
//   (a) targets: --calls scripted /start calls for --uids uids through HAProxy while hosts are killed (-9),
//       restarted, drained and undrained; duplicates (must be 0), the share of calls that could get a session
//       that got one (>= 95 %), sessions lost on hosts that stayed up (0).
//   (b) hop: GET /healthz and WebSocket frame (RFB Fence) round trips straight to a manager and through
//       HAProxy, medians and p95 side by side.
//   bench_cluster [--hosts N] [--slots N] [--calls N] [--uids N] [--fault-every N] [--interval-ms N] [--seed N]
//                 [--requests N] [--frames N] [--only targets|hop]
// Needs haproxy on PATH. No pass/fail: it prints tables; the targets' verdicts are words in the table.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "cluster_hop.hpp"
#include "cluster_targets.hpp"
#include "cluster_under_test.hpp"

namespace {

namespace bench = rfbsim::bench;

struct Options {
  int hosts = 3;
  int slots = 4;
  bench::TargetOptions targets;
  bench::HopOptions hop;
  std::string only;
};

Options parse(int argc, char** argv) {
  Options options;
  bench::CommandLine cli("bench_cluster",
                         "sim_manager hosts behind HAProxy: the cluster targets over scripted /start calls with hosts\n"
                         "killed, restarted and drained; the balancer's own hop.");
  cli.number("--hosts", options.hosts, 2, 32, "sim_manager hosts");
  cli.number("--slots", options.slots, 1, 64, "sessions per host");
  cli.number("--calls", options.targets.calls, 1, 1000000, "/start calls");
  cli.number("--uids", options.targets.uids, 1, 1000000, "participants calling");
  cli.number("--fault-every", options.targets.fault_every, 2, 1000000, "calls between faults");
  cli.number("--interval-ms", options.targets.interval_ms, 0, 60000, "ms between calls");
  cli.number("--seed", options.targets.seed, 0U, 1U << 30, "the calls' seed");
  cli.number("--requests", options.hop.requests, 1, 1000000, "requests timed on each path");
  cli.number("--frames", options.hop.frames, 1, 1000000, "frames timed on each path");
  bench::one_of(cli.app().add_option("--only", options.only, "run one part only"), {"targets", "hop"});
  cli.parse(argc, argv);
  options.targets.slots_per_host = options.slots;
  return options;
}

// The p-th percentile (0..100) by linear interpolation between closest ranks.
double percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0;
  std::sort(samples.begin(), samples.end());
  const double rank = p / 100.0 * static_cast<double>(samples.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(rank));
  const std::size_t high = std::min(low + 1, samples.size() - 1);
  return samples[low] + (samples[high] - samples[low]) * (rank - static_cast<double>(low));
}

std::string percent(int part, int whole) {
  return whole == 0 ? "-" : bench::fixed(100.0 * part / whole, 1) + " %";
}

void print_targets(const bench::TargetResult& r, const Options& o) {
  std::printf("\n(a) targets: %d /start calls for %d uids, %d hosts x %d slots, a call every %d ms + its own time, "
              "a fault every %d calls (%d kills + restarts, %d drains), %.1f s\n\n",
              r.calls, o.targets.uids, o.hosts, o.slots, o.targets.interval_ms, o.targets.fault_every, r.kills,
              r.drains, r.seconds);
  bench::Table table({"measure", "target", "value", "verdict"}, 2);
  table.add_row({"duplicate sessions (uid on two hosts)", "0", std::to_string(r.duplicates),
                 r.duplicates == 0 ? "met" : "MISSED"});
  const double share = r.eligible == 0 ? 0 : 100.0 * r.eligible_served / r.eligible;
  table.add_row({"calls that could get a session that got one", ">= 95 %",
                 percent(r.eligible_served, r.eligible) + " (" + std::to_string(r.eligible_served) + " of " +
                     std::to_string(r.eligible) + ")",
                 share >= 95.0 ? "met" : "MISSED"});
  table.add_row({"  of them new uids", "", percent(r.new_served, r.new_eligible) + " (" +
                                               std::to_string(r.new_served) + " of " + std::to_string(r.new_eligible) + ")",
                 ""});
  table.add_row({"sessions lost on hosts that stayed up", "0", std::to_string(r.lost_on_up_hosts),
                 r.lost_on_up_hosts == 0 ? "met" : "MISSED"});
  table.add_row({"sessions started", "", std::to_string(r.sessions_started), ""});
  std::string statuses;
  for (const auto& [status, count] : r.statuses) {
    statuses += (statuses.empty() ? "" : ", ") + std::to_string(status) + ": " + std::to_string(count);
  }
  table.add_row({"answers (last of each call)", "", statuses, ""});
  table.print();
}

void print_hop(const bench::HopSamples& s) {
  std::printf("\n(b) the balancer's hop, ms (same manager, interleaved; each request on a new connection; "
              "frames are RFB Fence round trips over the session's WebSocket)\n\n");
  bench::Table table({"round trip", "path", "n", "median", "p95", "mean"}, 2);
  const auto row = [&](const std::string& what, const std::string& path, const std::vector<double>& samples) {
    const bench::Summary summary = bench::summarize(samples);
    table.add_row({what, path, std::to_string(samples.size()), bench::fixed(percentile(samples, 50), 3),
                   bench::fixed(percentile(samples, 95), 3), bench::fixed(summary.mean, 3)});
  };
  row("GET /healthz", "direct", s.request_direct);
  row("GET /healthz", "HAProxy", s.request_proxied);
  row("WebSocket frame", "direct", s.frame_direct);
  row("WebSocket frame", "HAProxy", s.frame_proxied);
  table.print();
  std::printf("\nHAProxy adds %.3f ms per request and %.3f ms per frame round trip (medians).\n",
              percentile(s.request_proxied, 50) - percentile(s.request_direct, 50),
              percentile(s.frame_proxied, 50) - percentile(s.frame_direct, 50));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    // `--target bench` runs every bench: without HAProxy (a test-only package) this one says so and passes.
    if (std::system("command -v haproxy >/dev/null 2>&1") != 0) {
      std::printf("bench_cluster: skipped: no haproxy on PATH (sudo apt-get install haproxy)\n");
      return 0;
    }
    std::printf("bench_cluster on %s, load %s\n", bench::cpu_description().c_str(), bench::load_average().c_str());
    if (options.only != "hop") {
      // Sessions no browser opens live until the bench ends them (a light program: examples/minimal).
      rfbsim::test::ClusterUnderTest cluster({.hosts = options.hosts, .max_sessions = options.slots,
                                              .rate_limit = false,
                                              .config_yaml = rfbsim::test::minimal_sessions_yaml(3600)});
      print_targets(bench::run_targets(cluster, options.targets), options);
    }
    if (options.only != "targets") {
      rfbsim::test::ClusterUnderTest cluster({.hosts = 2, .max_sessions = 1, .rate_limit = false,
                                              .config_yaml = rfbsim::test::minimal_sessions_yaml()});
      print_hop(bench::measure_hop(cluster, options.hop));
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_cluster: %s\n", error.what());
    return 1;
  }
}
