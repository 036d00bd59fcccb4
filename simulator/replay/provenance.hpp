// SPDX-License-Identifier: GPL-2.0-or-later
// Provenance: whether a session log was made by this build from the scenario and map files as they are now.
// A replay repeats a session bit for bit only then (docs/replay.md says why); sim_replay refuses otherwise.
// Pure: compares strings.
#pragma once

#include <string>
#include <vector>

#include "app/session_setup.hpp"
#include "record/session_log.hpp"

namespace rfbsim::replay {

/// One field of session.json's `versions` that differs from what this build and these files give.
struct ProvenanceMismatch {
  std::string field;     ///< e.g. "versions.build"
  std::string recorded;  ///< the log's value
  std::string here;      ///< this build's value, or the hash of the file as it is now
  std::string what;      ///< what it means, e.g. "the scenario file /x/lab.yaml changed since the recording"
};

/// versions.rfbsim and versions.build against this build (rfbsim_version(), rfbsim_build_id()).
/// Checked before anything is loaded: another build may not even read the scenario the same way.
std::vector<ProvenanceMismatch> build_mismatches(const sim::SessionMeta& meta, const std::string& version,
                                                 const std::string& build);

/// versions.scenario_sha256 and map_sha256 against the hashes prepare_session computed from the files as
/// they are now (`now`: PreparedSession::info).
std::vector<ProvenanceMismatch> file_mismatches(const sim::SessionMeta& meta, const sim::SessionInfo& now);

/// One line for a mismatch: "versions.build differs: recorded 'GNU 12.2.0 Debug', this build 'GNU ...'
/// (...)".
std::string describe(const ProvenanceMismatch& mismatch);

}  // namespace rfbsim::replay
