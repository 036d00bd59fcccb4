// SPDX-License-Identifier: GPL-2.0-or-later
// A recorded session folder opened for replay: read and checked (docs/data.md), and its world rebuilt from
// session.json. sim_replay and sim_rfb --replay open recordings through these two calls, so that both refuse
// the same bad folders with the same words.
#pragma once

#include <filesystem>
#include <stdexcept>

#include "app/session_setup.hpp"
#include "record/session_log.hpp"

namespace rfbsim::replay {

/// A folder that cannot be replayed: missing, not a session, a log that is not as docs/data.md describes, or
/// a world that cannot be rebuilt. The message names the folder or file and the cause.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads and checks `dir`'s session.json, trajectories.csv and events.jsonl (a torn last line, left by a
/// kill, is dropped as sim::read_session does). Throws RecordingError.
sim::SessionLog read_recording(const std::filesystem::path& dir);

/// Builds the world `meta` was recorded in (setup_of(meta) through prepare_session). Throws RecordingError
/// when the scenario or its parameters no longer load.
sim::PreparedSession rebuild_world(const sim::SessionMeta& meta);

}  // namespace rfbsim::replay
