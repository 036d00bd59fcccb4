// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb --replay's loop (docs/replay.md): a recorded session shown to a watcher tick for tick, through the
// same server, painter and ready pipe as a live session (app/serving.hpp), the recording driven by
// app/watched_replay.hpp.
#pragma once

#include <atomic>

#include "app/options.hpp"

namespace rfbsim::sim {

/// Runs the replay of `options.replay` until its end and hold, or until `stop` (a signal). Returns the exit
/// status (0). Throws replay::RecordingError (and SessionLogError) for a recording that cannot be replayed,
/// std::runtime_error for a setup failure.
int run_replay(const SimOptions& options, const std::atomic<bool>& stop);

}  // namespace rfbsim::sim
