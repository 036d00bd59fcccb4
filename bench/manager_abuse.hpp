// SPDX-License-Identifier: GPL-2.0-or-later
// bench_manager --abuse: a real participant's time to first frame and frame rate through sim_manager, on an
// idle machine and then while another address holds thousands of idle half-open connections and hammers
// /start (manager_abuser.hpp), side by side in one run against one manager with its shipped abuse limits.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "manager_abuser.hpp"
#include "manager_probe.hpp"
#include "manager_process.hpp"

namespace rfbsim::bench {

/// What an abuse run does; every field has the default the bench uses.
struct AbuseOptions {
  int repetitions = 3;         ///< participant runs per phase (medians are reported)
  int seconds = 15;            ///< each run counts frames this long after its first frame
  int half_open = 2000;        ///< the abuser's idle half-open connections
  std::string from = "127.0.0.2";  ///< the abuser's source address
  int storm_per_second = 0;    ///< the abuser's /start pace; 0: as fast as answers come
  int ramp_seconds = 3;        ///< each abuser runs this long before its participant starts
};

/// One participant run: GET /start, a libvncclient through the relay, frames counted.
struct ParticipantRun {
  std::string error;      ///< empty when the run got its frames; otherwise what went wrong
  double first_ms = 0.0;  ///< GET /start sent -> first complete update
  double fps = 0.0;       ///< complete updates per second over AbuseOptions::seconds after the first
};

/// One phase (idle, or under abuse): its runs and what the manager and this process spent during them.
struct AbusePhase {
  std::vector<ParticipantRun> runs;
  double seconds = 0.0;          ///< the runs' wall time (abused runs: with the abuser's ramp)
  double manager_cpu_s = 0.0;    ///< sim_manager's CPU time over the phase
  double bench_cpu_s = 0.0;      ///< this process's (participant client, and the abuser in phase b)
  ProcessSample manager_after;   ///< sim_manager at the end of the phase's last run (before the abuser stops)
};

/// The whole run.
struct AbuseResult {
  AbusePhase idle, abused;
  AbuserCounts abuser;                     ///< summed over the abused runs
  std::map<std::string, double> counters;  ///< /metrics lines at the end of the last abused run (-1 if absent)
  long descriptor_limit = 0;               ///< this process's RLIMIT_NOFILE, which the manager inherited
};

/// Alternates runs of phase (a) and phase (b) against `manager` (started with its default abuse limits, after
/// this process raised its RLIMIT_NOFILE: pass the limit in force as `descriptor_limit`); a fresh abuser for each
/// abused run, and the sessions its storm started ended after it. The participant comes from 127.0.0.1
/// (tests/support's WsRfbBridge cannot choose its source address), the abuser from options.from.
AbuseResult run_abuse(const test::ManagerUnderTest& manager, const std::string& scenario, const AbuseOptions& options,
                      long descriptor_limit);

/// Prints both phases side by side, the medians and their ratios, the abuser's counts and the manager's
/// rejection counters.
void print_abuse(const AbuseResult& result, const AbuseOptions& options);

}  // namespace rfbsim::bench
