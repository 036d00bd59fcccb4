// SPDX-License-Identifier: GPL-2.0-or-later
// Replay test fixtures: in-process recordings, sim_replay as a process, file helpers.
#include "replay_fixtures.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>

#include "app/session_setup.hpp"
#include "record/session_writer.hpp"
#include "sim_process.hpp"

namespace rfbsim::test {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("rfbsim_replay_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir.parent_path());
  return dir;
}

Recording record_session(const RecordSpec& spec, const std::filesystem::path& dir) {
  sim::SessionSetup setup;
  setup.scenario = spec.scenario;
  setup.parameters = spec.parameters;
  setup.seed = spec.seed;
  setup.time_limit = spec.time_limit;
  sim::PreparedSession prepared = sim::prepare_session(setup);
  sim::Simulation& simulation = *prepared.simulation;
  sim::SessionInfo info = prepared.info;
  info.uid = "p-replay";
  info.width = spec.width;
  info.height = spec.height;
  info.codes = std::make_pair(std::string("OK-1"), std::string("LATE-2"));
  Recording recording;
  recording.dir = dir;
  {
    sim::SessionWriter writer(dir, info, simulation.world());
    sim::StudySession study(simulation, prepared.task, {"OK-1", "LATE-2"}, &writer);
    // sim_rfb's order: the tick's viewers and inputs, then the step.
    while (!study.over() && simulation.world().tick < spec.max_ticks) {
      const std::uint64_t tick = simulation.world().tick;
      if (tick == spec.connect_tick) study.client_connected(1, "0123456789abcdef", true);
      if (spec.script) spec.script(study, tick);
      study.step();
    }
    recording.outcome = study.outcome();
    recording.outcome_tick = study.task().outcome_tick();
    study.finish(study.over() ? sim::task_outcome_name(study.outcome()) : "signal");
  }
  recording.end_tick = simulation.world().tick;
  return recording;
}

Recording record_tutorial(const std::filesystem::path& dir) {
  RecordSpec spec;
  spec.scenario = "tutorial";
  spec.parameters = {{"avatar_goal", "8.4,5.4"}};  // 1 m back toward the start, reached after the turn
  spec.max_ticks = 60 * 120;
  // W until the walk is done, A until the turn is, Up until the camera step is, then W; all keys up at the end.
  spec.script = [held = -1](sim::StudySession& study, std::uint64_t) mutable {
    constexpr std::uint32_t keys[] = {'w', 'a', 0xff52, 'w'};
    const int step = study.task().status().step;
    if (study.outcome() == sim::TaskOutcome::None && step != held) {
      if (held >= 0) study.key(keys[held], false, 1);
      study.key(keys[step], true, 1);
      held = step;
    } else if (study.outcome() != sim::TaskOutcome::None && held >= 0) {
      study.key(keys[held], false, 1);
      held = -1;
    }
  };
  return record_session(spec, dir);
}

ReplayRun run_replay(const std::vector<std::string>& args) {
  const ExitResult result = run_to_exit(RFBSIM_SIM_REPLAY, args, std::chrono::minutes(5));
  ReplayRun run;
  run.output = result.output;
  if (result.status >= 0 && WIFEXITED(result.status)) run.exit_code = WEXITSTATUS(result.status);
  return run;
}

std::filesystem::path copy_session(const std::filesystem::path& from, const std::string& name) {
  const auto to = fresh_dir(name);
  std::filesystem::create_directories(to);
  for (const char* file : {"session.json", "trajectories.csv", "events.jsonl"}) {
    std::filesystem::copy_file(from / file, to / file);
  }
  return to;
}

std::vector<std::string> read_lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot read");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void write_lines(const std::filesystem::path& file, const std::vector<std::string>& lines) {
  std::ofstream out(file, std::ios::trunc);
  for (const std::string& line : lines) out << line << '\n';
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace rfbsim::test
