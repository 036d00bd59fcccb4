// SPDX-License-Identifier: GPL-2.0-or-later
// Duplicate participants: a uid with sessions on more than one host. sim_manager's uid registry gives every
// uid one host for good (docs/deployment.md), so such a uid means the registry was bypassed or hosts from two
// clusters were merged; the participant may have done the task twice. sim_report flags every session of it
// (duplicate_uid) so that the analysis can drop them; it does not drop them itself.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "session_metrics.hpp"

namespace rfbsim::report {

/// A uid seen on more than one host, with where.
struct DuplicateUid {
  std::string uid;
  std::vector<std::string> hosts;    ///< every host it has a session on, sorted, each once (at least 2)
  std::vector<std::string> folders;  ///< its sessions' folders, in report order
};

/// What report.md and report.html say above the table of duplicate participants.
inline constexpr const char* kDuplicatesNote =
    "These uids have sessions on more than one host: the participant may have taken part twice. Every session "
    "of them has duplicate_uid 1 in sessions.csv and is still in the statistics; drop them (or all but one) in "
    "the analysis.";

/// Finds the uids of `sessions` that have sessions on two or more hosts, sets `duplicate_uid` on each of
/// their sessions, and returns them sorted by uid. An empty uid (a session run by hand) is never a duplicate;
/// the same uid twice on one host (a link abandoned, then used) is not one either.
std::vector<DuplicateUid> flag_duplicate_uids(std::vector<SessionMetrics>& sessions);

/// How many different hosts `sessions` ran on.
std::size_t host_count(const std::vector<SessionMetrics>& sessions);

/// `items` joined with ", ".
std::string joined(const std::vector<std::string>& items);

/// One line for stderr: "uid 'p7' has sessions on 2 hosts: h1 (h1/1-p7), h2 (h2/3-p7)".
std::string duplicate_uid_line(const DuplicateUid& duplicate, const std::vector<SessionMetrics>& sessions);

}  // namespace rfbsim::report
