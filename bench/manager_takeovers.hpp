// SPDX-License-Identifier: GPL-2.0-or-later
// bench_manager --takeover-storm: WebSocket upgrades to one's own session from many source addresses, each
// completed and then left open and unread (as a script that opens and forgets), paced over a few seconds; what
// it costs the manager: log growth, takeover lines, CPU time and memory. Issue 31's row: 2,000 upgrades from 60
// addresses in 10 s. Given a second manager (--manager-before), both run side by side in one table.
#pragma once

#include <string>
#include <vector>

#include "manager_session.hpp"

namespace rfbsim::bench {

struct TakeoverStormOptions {
  int upgrades = 2000;  ///< upgrades in all
  int addresses = 60;   ///< source addresses 127.0.1.10 ... (Linux routes 127/8 to loopback)
  int seconds = 10;     ///< the upgrades are spread evenly over this long
};

/// One manager's storm.
struct TakeoverStormResult {
  std::string label;               ///< which manager ("after", "before", or its path)
  int switched = 0;                ///< upgrades answered 101
  int rate_limited = 0;            ///< answered 429
  int other = 0;                   ///< answered otherwise, or not at all
  double takeovers = 0;            ///< rfbsim_takeovers_total afterwards
  double log_kib = 0;              ///< the manager's log grew by this much over the storm
  int takeover_lines = 0;          ///< of it, lines about a takeover (suppressed-count lines included)
  double cpu_s = 0;                ///< the manager's CPU time over the storm and a second after it
  double rss_before_mib = 0, rss_after_mib = 0;
};

/// Runs the storm against a fresh manager `run.program` (its log in `run.log`, which should start empty).
TakeoverStormResult run_takeover_storm(const ManagerRun& run, const std::string& label,
                                       const TakeoverStormOptions& options);

/// Prints the runs side by side.
void print_takeover_storm(const std::vector<TakeoverStormResult>& results, const TakeoverStormOptions& options);

}  // namespace rfbsim::bench
