// SPDX-License-Identifier: GPL-2.0-or-later
// What a running process holds, read from /proc: resident memory, open descriptors, CPU time. bench_manager
// samples sim_manager with it during a soak and around an abuse run.
#pragma once

#include <sys/types.h>

#include <string>

namespace rfbsim::bench {

/// One look at a process.
struct ProcessSample {
  double rss_mib = 0.0;  ///< VmRSS, MiB
  int descriptors = 0;   ///< entries of /proc/PID/fd
  double cpu_s = 0.0;    ///< user + system CPU time since it started, seconds
};

/// Samples process `pid`; throws std::runtime_error when it has exited (a zombie included) or /proc cannot be read.
ProcessSample sample_process(pid_t pid);

/// Raises this process's soft RLIMIT_NOFILE to at least `wanted` (up to the hard limit); returns the soft
/// limit in force afterwards. Children started later inherit it.
long raise_descriptor_limit(long wanted);

}  // namespace rfbsim::bench
