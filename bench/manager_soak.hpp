// SPDX-License-Identifier: GPL-2.0-or-later
// bench_manager --soak: sessions cycled through sim_manager's relay for many minutes while its resident memory
// and open descriptors are sampled, to show that nothing a session leaves behind accumulates.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "manager_probe.hpp"
#include "manager_process.hpp"

namespace rfbsim::bench {

/// What a soak does; every field has the default the bench uses.
struct SoakOptions {
  double minutes = 30.0;         ///< new sessions are started for this long; the run then waits for the last
  int sessions_per_minute = 10;  ///< planned pace of new sessions (300 in 30 minutes)
  int max_sessions = 4;          ///< at most this many at once (the manager's --max-sessions)
  int watch_seconds = 5;         ///< each session's client receives frames this long, then disconnects
  int sample_seconds = 10;       ///< between samples of the manager
  /// Every idle_every-th session is not ended through the admin API but left to the manager's idle timeout
  /// (soak_idle_timeout_s), so that both ways a session ends are cycled. 0: all ended through the API.
  int idle_every = 3;
};

/// The manager's --idle-timeout-s during a soak: sessions left to it end this long after their client left.
inline constexpr int kSoakIdleTimeoutS = 10;

/// One sample of the manager during a soak.
struct SoakSample {
  double at_s = 0.0;        ///< seconds since the soak began
  int started = 0;          ///< sessions started so far (302 received)
  int finished = 0;         ///< sessions whose index row reached a final state, failures included
  int failed = 0;           ///< sessions that did not get through start, frames and end (see SoakResult::errors)
  int in_flight = 0;        ///< sessions between /start and their final state now
  std::uint64_t updates = 0;  ///< complete framebuffer updates received by all clients so far
  ProcessSample manager;    ///< the manager's memory, descriptors and CPU time
};

/// A whole soak.
struct SoakResult {
  std::vector<SoakSample> samples;             ///< in time order; the last is taken once every session is over
  std::map<std::string, int> final_states;    ///< index state at the end of each session -> count
  std::vector<std::string> errors;             ///< the first few failures, verbatim
  double seconds = 0.0;                        ///< the soak's wall time
};

/// Cycles sessions through `manager` (started with max_sessions and kSoakIdleTimeoutS) for options.minutes:
/// each one GET /start, a libvncclient through a WsRfbBridge on its /s/<token>/ws for watch_seconds,
/// disconnect, then the admin end (or the idle timeout), until the index says it is over. Samples the
/// manager every sample_seconds. A session that fails is counted and the soak goes on.
SoakResult run_soak(const test::ManagerUnderTest& manager, const std::string& scenario, const SoakOptions& options);

/// Prints the samples as a table and the growth from the first sample to the last.
void print_soak(const SoakResult& result, const SoakOptions& options);

}  // namespace rfbsim::bench
