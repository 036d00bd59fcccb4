// SPDX-License-Identifier: GPL-2.0-or-later
// Opening a recording: the folder, its log, its world.
#include "replay/recording.hpp"

#include <system_error>

#include "replay/session_replay.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::replay {

sim::SessionLog read_recording(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw RecordingError(dir.string() + ": no such folder");
  try {
    return sim::read_session(dir);
  } catch (const sim::SessionLogError& e) {
    throw RecordingError(std::string("cannot read the session: ") + e.what());
  }
}

sim::PreparedSession rebuild_world(const sim::SessionMeta& meta) {
  try {
    return sim::prepare_session(setup_of(meta));
  } catch (const sim::ScenarioError& e) {
    throw RecordingError("cannot rebuild the session's world from " +
                         (meta.scenario_file.empty() ? std::string("the built-in test room") : meta.scenario_file) +
                         ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw RecordingError(std::string("cannot rebuild the session's world: ") + e.what());
  }
}

}  // namespace rfbsim::replay
