// SPDX-License-Identifier: GPL-2.0-or-later
// SessionReplay: a recorded session's world rebuilt and driven by its recorded inputs. It builds the world
// with prepare_session from session.json (scenario file, parameters, seed, tick rate, time limit), runs it
// through a StudySession as sim_rfb did (so both take the same path through the same code), and applies
// every input of events.jsonl at its tick, before that tick's step, in file order: keys, pointer events and
// viewers coming and going (the first viewer starts the task clock, exactly as live). sim_replay has the
// replay record its own session data, which it compares with the log; sim_rfb --replay shows it live and
// records none (docs/replay.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "app/session_setup.hpp"
#include "app/study_session.hpp"
#include "record/session_log.hpp"
#include "record/session_writer.hpp"

namespace rfbsim::replay {

/// The SessionSetup that rebuilds the world of `meta` (its scenario_file, parameters, seed, tick rate and
/// time limit).
sim::SessionSetup setup_of(const sim::SessionMeta& meta);

/// The tick the recorded run ended at: session.json's end_tick, or after a crash (no end_tick) the last
/// tick in trajectories.csv (0 without rows).
std::uint64_t recorded_end_tick(const sim::SessionLog& log);

class SessionReplay {
 public:
  /// Takes the world `prepared` (from setup_of(log.meta)) and records into `out_dir` (created; it must not
  /// hold session data already), or nowhere when `out_dir` is empty. `log` must outlive this. Throws
  /// std::runtime_error when `out_dir` cannot be written.
  SessionReplay(const sim::SessionLog& log, sim::PreparedSession prepared, const std::filesystem::path& out_dir);
  ~SessionReplay();
  SessionReplay(const SessionReplay&) = delete;
  SessionReplay& operator=(const SessionReplay&) = delete;

  /// Applies the recorded inputs of the current tick (those not applied yet). Call before drawing the tick
  /// and before step(); step() calls it too. Throws sim::SessionLogError for an input out of tick order.
  void apply_inputs();
  /// Applies the current tick's inputs, then steps once.
  void step();
  /// Whether the replay reached the recorded end tick.
  [[nodiscard]] bool done() const { return world().tick >= end_tick_; }
  /// Applies the inputs recorded at the end tick (after the last step), and closes the replay's session
  /// data (if any) with the recorded end reason. Call once, when done().
  void finish();

  [[nodiscard]] std::uint64_t end_tick() const { return end_tick_; }
  [[nodiscard]] const sim::World& world() const { return simulation_->world(); }
  [[nodiscard]] const sim::StudySession& study() const { return *study_; }
  [[nodiscard]] const std::filesystem::path& out_dir() const { return out_dir_; }
  /// Inputs applied so far (keys, pointer events, viewers).
  [[nodiscard]] std::size_t inputs_applied() const { return inputs_applied_; }

 private:
  void apply(const sim::Event& event);

  const sim::SessionLog& log_;
  std::filesystem::path out_dir_;
  std::uint64_t end_tick_ = 0;
  std::unique_ptr<sim::Simulation> simulation_;
  std::unique_ptr<sim::SessionWriter> writer_;
  std::unique_ptr<sim::StudySession> study_;
  std::size_t next_event_ = 0;
  std::size_t inputs_applied_ = 0;
};

}  // namespace rfbsim::replay
