// SPDX-License-Identifier: GPL-2.0-or-later
// What the replay tests share: sessions recorded in-process through StudySession (as sim_rfb records them,
// with a scripted participant), sim_replay run as a process, and small file helpers.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/study_session.hpp"

namespace rfbsim::test {

/// A fresh, empty folder under the temporary directory, unique to this process.
std::filesystem::path fresh_dir(const std::string& name);

/// How to record one session in-process.
struct RecordSpec {
  std::string scenario = "lab";  ///< name or path
  std::vector<std::pair<std::string, std::string>> parameters;
  std::optional<std::uint64_t> seed;  ///< as sim_rfb's --seed; unset = the scenario's
  std::optional<double> time_limit;  ///< s
  int width = 320, height = 240;     ///< the frame session.json records (the video's size)
  std::uint64_t connect_tick = 0;    ///< when the viewer arrives (and the task clock starts)
  std::uint64_t max_ticks = 600;     ///< ended with reason "signal" here unless the session is over first
  /// The participant: called before every step with the session and its tick (keys go in here).
  std::function<void(sim::StudySession&, std::uint64_t)> script;
};

/// What was recorded.
struct Recording {
  std::filesystem::path dir;
  std::uint64_t end_tick = 0;
  std::optional<std::uint64_t> outcome_tick;
  sim::TaskOutcome outcome = sim::TaskOutcome::None;
};

/// Records `spec` into `dir` (session.json, trajectories.csv, events.jsonl).
Recording record_session(const RecordSpec& spec, const std::filesystem::path& dir);

/// The tutorial completed with keys (W for the walk, A for the turn, Up for the camera, W to the goal),
/// with codes OK-1 / LATE-2, as tests/app/study_session_test.cpp plays it.
Recording record_tutorial(const std::filesystem::path& dir);

/// What sim_replay did: its exit code (-1: no normal exit) and its stdout and stderr together.
struct ReplayRun {
  int exit_code = -1;
  std::string output;
};

/// Runs the sim_replay under test with `args`.
ReplayRun run_replay(const std::vector<std::string>& args);

/// Copies a session folder's three files into a fresh folder `name`.
std::filesystem::path copy_session(const std::filesystem::path& from, const std::string& name);

/// A file's lines (without their newlines), and writing them back (each with one).
std::vector<std::string> read_lines(const std::filesystem::path& file);
void write_lines(const std::filesystem::path& file, const std::vector<std::string>& lines);

}  // namespace rfbsim::test
