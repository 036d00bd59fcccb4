// SPDX-License-Identifier: GPL-2.0-or-later
// bench_cluster (a): the targets. Scripted /start calls for a fixed set of uids through HAProxy while
// hosts are killed (SIGKILL), restarted, drained and undrained, and sessions end to make room; afterwards, what
// the participants got and what the hosts' own indexes say.
#pragma once

#include <map>
#include <string>

#include "cluster_under_test.hpp"

namespace rfbsim::bench {

/// The script's size.
struct TargetOptions {
  int calls = 1000;      ///< /start calls
  int uids = 300;        ///< distinct uids, each call picks one at random
  unsigned seed = 1;     ///< the random choices (uids, hosts, sessions to end)
  int fault_every = 100;  ///< calls between faults (kill, then drain, in turn); the fault is undone halfway
  int slots_per_host = 4;  ///< the cluster's --max-sessions: sessions are ended to keep 3/4 of the slots taken
  /// Pause before each call, ms: participants arrive spread out, and HAProxy learns a host's load from its
  /// agent once a second (agent-inter), so back-to-back calls meet a host that filled a moment ago.
  int interval_ms = 200;
};

/// What the run found.
struct TargetResult {
  int calls = 0;
  /// Calls for a uid that could get a session: a new uid while some live, undrained host had a free slot,
  /// or a known uid whose home (the host the registry gave it) was up and had its session or a free slot.
  int eligible = 0;
  int eligible_served = 0;  ///< of those, answered with a session (302)
  int new_eligible = 0, new_served = 0;  ///< the part of both that was a new uid
  /// uids with sessions on more than one host (the hosts' indexes, merged), plus any 302 that named another
  /// host than the uid's home: must be 0.
  int duplicates = 0;
  /// Sessions live on a host that was not killed which ended without the bench ending them: must be 0.
  int lost_on_up_hosts = 0;
  int sessions_started = 0;  ///< new sessions (302s with a token not seen before)
  int kills = 0, restarts = 0, drains = 0;
  std::map<int, int> statuses;  ///< the last answer's status -> calls
  double seconds = 0;
};

/// Runs the script on `cluster` (minimal sessions, any size).
TargetResult run_targets(test::ClusterUnderTest& cluster, const TargetOptions& options);

}  // namespace rfbsim::bench
