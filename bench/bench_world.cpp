// SPDX-License-Identifier: GPL-2.0-or-later
// bench_world: what one simulated world costs. For the warehouse (15 people, physics) the time of each
// stage per tick (crowd, physics, the whole Simulation::step); for both shipped scenes the time to build
// and render one 1280x720 frame off-screen. Prints tables; never passes or fails.
//
//   bench_world [--ticks N] [--frames N] [--size WxH] [--samples N] [--scenarios warehouse,lab]
//   --samples: MSAA samples (default: automatic, as sim_rfb: 4 on a GPU, none on llvmpipe)
//
// llvmpipe's thread count comes from LP_NUM_THREADS (unset: one per core); the table says which.
#include <GL/gl.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/simulation.hpp"
#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "crowd/crowd.hpp"
#include "physics/physics_world.hpp"
#include "render/gl_renderer.hpp"
#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "scenario/scenario.hpp"

namespace bench = rfbsim::bench;
namespace sim = rfbsim::sim;
using bench::Clock;

namespace {

struct Options {
  int ticks = 3600;  // one simulated minute at 60 Hz
  int frames = 120;
  bench::Size size{1280, 720};
  std::vector<std::string> scenarios{"warehouse", "lab"};
  int samples = rfbsim::OffscreenGLOptions::kAutoSamples;  // MSAA, as sim_rfb renders unless told
};

sim::Scenario load(const std::string& name) {
  return sim::load_scenario(sim::find_scenario(name, {RFBSIM_SOURCE_SCENARIOS}));
}

// The participant walks and turns, so the avatar takes part in contacts and the view keeps changing.
void script_keys(sim::Simulation& simulation, int tick) {
  if (tick == 0) simulation.apply_key('w', true);
  if (tick % 240 == 0) simulation.apply_key('a', true);
  if (tick % 240 == 30) simulation.apply_key('a', false);
}

void bench_step(const Options& options, const std::string& name) {
  const sim::Scenario scenario = load(name);
  const sim::SimulationParams params;

  // The stages on their own, in Simulation::step's order, on one world.
  sim::World world = sim::make_world(scenario);
  sim::Crowd crowd(world, scenario.crowd, params.crowd);
  world.people = crowd.spawn();
  sim::PhysicsWorld physics(world, params.physics);
  std::vector<double> crowd_ms;
  std::vector<double> physics_ms;
  for (int tick = 0; tick < options.ticks; ++tick) {
    world.avatar.speed = 1.0;  // keep the avatar walking into whatever is ahead
    const auto t0 = Clock::now();
    crowd.step(world, params.dt);
    const auto t1 = Clock::now();
    physics.step(world, params.dt);
    const auto t2 = Clock::now();
    ++world.tick;
    crowd_ms.push_back(bench::ms_between(t0, t1));
    physics_ms.push_back(bench::ms_between(t1, t2));
  }

  // The whole step as sim_rfb runs it (input, avatar, crowd, physics, gait).
  sim::Simulation simulation(params, sim::make_world(scenario), scenario.crowd);
  std::vector<double> total_ms;
  for (int tick = 0; tick < options.ticks; ++tick) {
    script_keys(simulation, tick);
    const auto t0 = Clock::now();
    simulation.step();
    total_ms.push_back(bench::ms_between(t0, Clock::now()));
  }

  bench::Table table({"scenario", "stage", "ticks", "p50 ms", "p90 ms", "p99 ms", "mean ms", "max ms"});
  const auto row = [&](const char* stage, const std::vector<double>& samples) {
    const bench::Summary s = bench::summarize(samples);
    table.add_row({name, stage, std::to_string(s.n), bench::fixed(s.p50, 3), bench::fixed(s.p90, 3),
                   bench::fixed(s.p99, 3), bench::fixed(s.mean, 3), bench::fixed(s.max, 3)});
  };
  row("crowd", crowd_ms);
  row("physics", physics_ms);
  row("Simulation::step", total_ms);
  std::printf("\n%s: %zu people, %zu props, dt %.4f s\n", name.c_str(), world.people.size(), world.props.size(),
              params.dt);
  table.print();
}

void bench_render(const Options& options) {
  rfbsim::OffscreenGLOptions gl_options;
  gl_options.width = options.size.width;
  gl_options.height = options.size.height;
  gl_options.samples = options.samples;
  rfbsim::OffscreenGL gl(gl_options);
  sim::GlRenderer renderer;
  const char* threads = std::getenv("LP_NUM_THREADS");
  std::printf("\nrender %s with %s, LP_NUM_THREADS=%s\n", options.size.text().c_str(), gl.renderer().c_str(),
              threads != nullptr ? threads : "(unset: one per core)");
  bench::Table table({"scenario", "stage", "frames", "items", "draw calls", "p50 ms", "p90 ms", "mean ms"});
  for (const std::string& name : options.scenarios) {
    const sim::Scenario scenario = load(name);
    sim::Simulation simulation(sim::SimulationParams{}, sim::make_world(scenario), scenario.crowd);
    std::vector<double> build_ms;
    std::vector<double> draw_ms;
    std::vector<double> readback_ms;
    std::vector<double> frame_ms;  // the three together: what one frame costs sim_rfb's thread
    std::size_t items = 0;
    std::size_t draw_calls = 0;
    for (int frame = 0; frame < options.frames + 10; ++frame) {
      for (int t = 0; t < 2; ++t) {  // 60 Hz ticks, 30 frames per second
        script_keys(simulation, frame * 2 + t);
        simulation.step();
      }
      gl.begin_frame();
      const auto t0 = Clock::now();
      const sim::Scene scene = sim::build_scene(simulation.world());
      const auto t1 = Clock::now();
      renderer.draw(scene, gl.width(), gl.height());
      glFinish();
      const auto t2 = Clock::now();
      (void)gl.read_frame();
      const auto t3 = Clock::now();
      if (frame < 10) continue;  // warm-up: shader compilation, first uploads
      items = scene.items.size();
      draw_calls = renderer.last_draw_calls();
      build_ms.push_back(bench::ms_between(t0, t1));
      draw_ms.push_back(bench::ms_between(t1, t2));
      readback_ms.push_back(bench::ms_between(t2, t3));
      frame_ms.push_back(bench::ms_between(t0, t3));
    }
    const auto row = [&](const char* stage, const std::vector<double>& samples) {
      const bench::Summary s = bench::summarize(samples);
      table.add_row({name, stage, std::to_string(s.n), std::to_string(items), std::to_string(draw_calls),
                     bench::fixed(s.p50, 2), bench::fixed(s.p90, 2), bench::fixed(s.mean, 2)});
    };
    row("build scene", build_ms);
    row("render", draw_ms);
    row("read back", readback_ms);
    row("whole frame", frame_ms);
  }
  table.print();
}

Options parse(int argc, char** argv) {
  Options options;
  bench::CommandLine cli("bench_world",
                         "The sim step per tick (crowd, physics, total) and the render per frame of the shipped scenes.");
  cli.number("--ticks", options.ticks, 1, 10'000'000, "ticks stepped");
  cli.number("--frames", options.frames, 1, 100'000, "frames rendered per scene");
  cli.size("--size", options.size, "the frame's size");
  cli.number("--samples", options.samples, 0, 16, "MSAA samples")
      ->default_str("auto: 4 on a GPU, none on a software rasterizer");
  cli.list("--scenarios", options.scenarios, [](const std::string& item) { return item; }, "scenes rendered");
  cli.parse(argc, argv);
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    std::printf("bench_world: CPU %s; load average %s at start\n", bench::cpu_description().c_str(),
                bench::load_average().c_str());
    bench_step(options, "warehouse");
    bench_render(options);
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_world: %s\n", error.what());
    return 2;
  }
}
