// SPDX-License-Identifier: GPL-2.0-or-later
// WatchedReplay: open, check, play, describe.
#include "app/watched_replay.hpp"

#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/session_setup.hpp"
#include "replay/provenance.hpp"
#include "replay/recording.hpp"

namespace rfbsim::sim {

namespace {

// A live replay that departs from the recording would show the watcher something the walker never saw, so
// any difference of build or files refuses it (sim_replay's --force has no counterpart here).
void refuse_mismatches(const std::vector<replay::ProvenanceMismatch>& mismatches, const std::filesystem::path& dir) {
  if (mismatches.empty()) return;
  std::string text = "refusing to replay " + dir.string() + ":";
  for (const replay::ProvenanceMismatch& m : mismatches) text += "\n  " + replay::describe(m);
  throw replay::RecordingError(text + "\n  a replay repeats a session only with the same build and files");
}

}  // namespace

WatchedReplay::WatchedReplay(const std::filesystem::path& dir) : dir_(dir), log_(replay::read_recording(dir)) {
  // The same build first (another one may not even read the scenario alike), then the same files.
  refuse_mismatches(replay::build_mismatches(log_.meta, rfbsim_version(), rfbsim_build_id()), dir_);
  PreparedSession prepared = replay::rebuild_world(log_.meta);
  refuse_mismatches(replay::file_mismatches(log_.meta, prepared.info), dir_);
  // An empty out_dir: the replay records nothing, and nothing is ever written into the recording's folder.
  replay_ = std::make_unique<replay::SessionReplay>(log_, std::move(prepared), std::filesystem::path());
}

WatchedReplay::~WatchedReplay() = default;

TaskText WatchedReplay::text() const {
  const TaskMonitor& task = replay_->study().task();
  TaskText text = watched_task_text(task.spec(), task.status());
  if (ended_ && !watcher_code_.empty()) {
    // The watcher's own code, like a walker's at their outcome: the survey hears it too, the picture shows it
    // for a participant whose survey is not listening.
    text.corner.clear();
    text.centre = {"The recording has ended. Thank you!", "Your completion code:", watcher_code_};
  }
  return text;
}

bool WatchedReplay::advance(int ticks) {
  for (int i = 0; i < ticks && !replay_->done(); ++i) replay_->step();
  if (replay_->done() && !ended_) {
    replay_->finish();  // the inputs of the end tick, as recorded after the last step
    ended_ = true;
  }
  return ended_;
}

std::string WatchedReplay::status_member() const {
  const nlohmann::json replay = {{"recording", dir_.string()},
                                 {"uid", log_.meta.uid},
                                 {"end_tick", end_tick()},
                                 {"ended", ended_}};
  // A folder name need not be UTF-8: replaced, not thrown over.
  return "\"replay\":" + replay.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void check_watch_data_dir(const std::filesystem::path& data_dir, const std::filesystem::path& recording) {
  std::error_code ec_data, ec_recording;
  const std::filesystem::path data = std::filesystem::weakly_canonical(data_dir, ec_data);
  const std::filesystem::path source = std::filesystem::weakly_canonical(recording, ec_recording);
  if (ec_data || ec_recording) return;  // a recording that cannot be resolved is refused when it is opened
  const std::filesystem::path inside = data.lexically_relative(source);
  if (!inside.empty() && *inside.begin() != "..") {
    throw replay::RecordingError("--data-dir " + data_dir.string() + " is inside the recording " + recording.string() +
                                 ": give another folder (a replay never writes into its recording)");
  }
}

std::string with_status_member(std::string status, const std::string& member) {
  if (status.empty() || status.back() != '}') return status;  // not an object: left as it is
  status.pop_back();
  return status + (status.size() > 1 ? "," : "") + member + "}";
}

}  // namespace rfbsim::sim
