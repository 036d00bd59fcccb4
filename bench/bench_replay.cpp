// SPDX-License-Identifier: GPL-2.0-or-later
// bench_replay: what sim_replay costs. Records warehouse sessions in-process (its crowd and robot, a scripted
// participant walking and turning, as sim_rfb would record them), then replays each several times through
// the same job sim_replay runs: the pose check alone, a video of the participant's view, a video from above.
// Prints the replay speed (simulated seconds per wall second, median of the runs) and the cost of a video
// frame (render = scene, HUD and read back; encode = RGBA to YUV and H.264). Never passes or fails.
//
//   bench_replay [--seconds S] [--runs N] [--sessions N] [--size WxH] [--scenario NAME]
//
// llvmpipe's thread count comes from LP_NUM_THREADS (unset: one per core); the table says which.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/session_setup.hpp"
#include "app/study_session.hpp"
#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "record/session_writer.hpp"
#include "replay_job.hpp"

namespace bench = rfbsim::bench;
namespace sim = rfbsim::sim;
namespace replay = rfbsim::replay;
using bench::Clock;

namespace {

struct Options {
  int seconds = 20;  // simulated seconds per session
  int runs = 3;      // replays per session and mode
  int sessions = 2;
  bench::Size size{1280, 720};  // the recorded frame: the video's size
  std::string scenario = "warehouse";
};

// The participant walks and turns (bench_world's script), from the first tick with a viewer.
void script_keys(sim::StudySession& study, std::uint64_t tick) {
  if (tick == 0) study.key('w', true, 1);
  if (tick % 240 == 0) study.key('a', true, 1);
  if (tick % 240 == 30) study.key('a', false, 1);
}

// Records one session of `options.seconds` into `dir`; returns the mean step time, ms.
double record(const Options& options, std::uint64_t seed, const std::filesystem::path& dir) {
  sim::SessionSetup setup;
  setup.scenario = options.scenario;
  setup.seed = seed;
  sim::PreparedSession prepared = sim::prepare_session(setup);
  sim::SessionInfo info = prepared.info;
  info.width = options.size.width;
  info.height = options.size.height;
  sim::SessionWriter writer(dir, info, prepared.simulation->world());
  sim::StudySession study(*prepared.simulation, prepared.task, {}, &writer);
  study.client_connected(1, "0123456789abcdef", true);
  const auto ticks = static_cast<std::uint64_t>(options.seconds) * static_cast<std::uint64_t>(setup.tick_hz);
  const auto start = Clock::now();
  while (prepared.simulation->world().tick < ticks && !study.over()) {
    script_keys(study, prepared.simulation->world().tick);
    study.step();
  }
  const double ms = bench::ms_between(start, Clock::now()) / static_cast<double>(ticks);
  study.finish("signal");
  return ms;
}

struct Mode {
  const char* name;
  bool video;
  replay::View view;
};

void run(const Options& options) {
  const auto root = std::filesystem::temp_directory_path() / ("bench_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  std::vector<std::filesystem::path> sessions;
  std::vector<double> step_ms;
  for (int i = 0; i < options.sessions; ++i) {
    sessions.push_back(root / ("session_" + std::to_string(i)));
    step_ms.push_back(record(options, 1 + static_cast<std::uint64_t>(i), sessions.back()));
  }
  std::printf("recorded %d %s sessions of %d simulated s at %s (step %.2f ms/tick while recording)\n", options.sessions,
              options.scenario.c_str(), options.seconds, options.size.text().c_str(), bench::summarize(step_ms).p50);

  const Mode modes[] = {{"check only", false, replay::View::Participant},
                        {"video, participant view", true, replay::View::Participant},
                        {"video, top view", true, replay::View::Top}};
  bench::Table table({"mode", "size", "replays", "wall s p50", "sim s / wall s p50", "frames", "render ms p50",
                      "encode ms p50", "frame ms p50", "video kB"},
                     2);
  std::string renderer, encoder;
  for (const Mode& mode : modes) {
    std::vector<double> speed, wall, render, encode, frame;
    std::int64_t frames = 0, bytes = 0;
    for (const auto& session : sessions) {
      for (int r = 0; r < options.runs; ++r) {
        replay::ReplayOptions replay_options;
        replay_options.session_dir = session;
        replay_options.quiet = true;
        replay_options.view = mode.view;
        if (mode.video) replay_options.video = root / "bench.mp4";
        const auto start = Clock::now();
        const replay::ReplayResult result = replay::replay_session(replay_options);
        const double seconds = bench::ms_between(start, Clock::now()) / 1000.0;
        if (result.exit_status != replay::kExitMatch) {
          throw std::runtime_error(std::string(mode.name) + ": " + result.error +
                                   (result.report.empty() ? std::string() : result.report.front()));
        }
        wall.push_back(seconds);
        speed.push_back(result.simulated_s / seconds);
        for (std::size_t f = 0; f < result.render_ms.size(); ++f) {
          render.push_back(result.render_ms[f]);
          encode.push_back(result.encode_ms[f]);
          frame.push_back(result.render_ms[f] + result.encode_ms[f]);
        }
        frames = result.frames;
        bytes = result.video_bytes;
        if (!result.renderer.empty()) renderer = result.renderer;
        if (!result.encoder.empty()) encoder = result.encoder;
      }
    }
    const auto p50 = [](const std::vector<double>& v, int decimals) {
      return v.empty() ? std::string("-") : bench::fixed(bench::summarize(v).p50, decimals);
    };
    table.add_row({mode.name, mode.video ? options.size.text() : "-", std::to_string(wall.size()), p50(wall, 2),
                   p50(speed, 2), mode.video ? std::to_string(frames) : "-", p50(render, 2), p50(encode, 2), p50(frame, 2),
                   mode.video ? std::to_string(bytes / 1000) : "-"});
  }
  const char* threads = std::getenv("LP_NUM_THREADS");
  std::printf("rendering with %s, LP_NUM_THREADS=%s; encoder %s (CRF 23, veryfast)\n", renderer.c_str(),
              threads != nullptr ? threads : "(unset: one per core)", encoder.c_str());
  table.print();
  std::filesystem::remove_all(root);
}

Options parse(int argc, char** argv) {
  Options options;
  bench::CommandLine cli("bench_replay",
                         "sim_replay: replay speed with and without video (both views), render and encode per frame.");
  cli.number("--seconds", options.seconds, 1, 3600, "simulated seconds per session");
  cli.number("--runs", options.runs, 1, 100, "replays per session and mode");
  cli.number("--sessions", options.sessions, 1, 100, "sessions recorded");
  cli.size("--size", options.size, "the recorded frame: the video's size");
  cli.text("--scenario", options.scenario, "the sessions' scenario");
  cli.parse(argc, argv);
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    std::printf("bench_replay: CPU %s; load average %s at start\n", bench::cpu_description().c_str(),
                bench::load_average().c_str());
    run(options);
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_replay: %s\n", error.what());
    return 2;
  }
}
