// SPDX-License-Identifier: GPL-2.0-or-later
// A hand-made session written to a scratch folder and measured as sim_report measures it: read back as a session
// log, sampled, and turned into its per-session metrics.
#pragma once

#include "record/session_log.hpp"
#include "session_files.hpp"
#include "session_metrics.hpp"
#include "session_samples.hpp"

namespace rfbsim::report::test {

/// Writes `spec` into `scratch` and returns the metrics the report computes for it.
inline SessionMetrics measure(const ScratchDir& scratch, const SessionSpec& spec) {
  write_session(scratch.path(), spec);
  const auto log = rfbsim::sim::read_session(scratch.path());
  return session_metrics(log, assemble_samples(log));
}

}  // namespace rfbsim::report::test
