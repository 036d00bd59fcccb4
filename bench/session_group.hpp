// SPDX-License-Identifier: GPL-2.0-or-later
// What one session costs, read from /proc: every process of its process group (sim_manager puts each session
// program in a group of its own, led by the pid in the index row, so an x11 session's launcher, Xvnc and the
// program all count), with their CPU time and resident memory. bench_session_kinds compares kinds with it.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace rfbsim::bench {

/// One process of a group, as /proc showed it at one moment.
struct GroupMember {
  pid_t pid = 0;
  std::string name;      ///< its command name (/proc/PID/comm: at most 15 characters)
  double cpu_s = 0.0;    ///< user + system CPU time since it started, seconds
  double rss_mib = 0.0;  ///< VmRSS, MiB (0 for a zombie)
};

/// Every live process whose process group is `pgid`, in pid order; empty when there is none. A process that
/// exits while it is being read is left out (that is a race, not an error).
std::vector<GroupMember> group_members(pid_t pgid);

/// Sum of the members' CPU time, seconds.
double group_cpu_s(const std::vector<GroupMember>& members);
/// Sum of the members' VmRSS, MiB.
double group_rss_mib(const std::vector<GroupMember>& members);
/// CPU seconds the group used from `before` to `after`: per pid, its time at `after` less its time at `before`
/// (all of it for a process started meanwhile). A process that exited meanwhile is lost to both looks.
double group_cpu_between(const std::vector<GroupMember>& before, const std::vector<GroupMember>& after);
/// Each member of `after` as "NAME CORES cores, RSS MiB" (its CPU seconds since `before` over `wall_s`),
/// joined with " + " in pid order (so a launcher comes before what it started).
std::string group_breakdown(const std::vector<GroupMember>& before, const std::vector<GroupMember>& after,
                            double wall_s);

}  // namespace rfbsim::bench
