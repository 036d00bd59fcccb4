// SPDX-License-Identifier: GPL-2.0-or-later
// bench_frame: where one frame's time goes, stage by stage, on the demo world.
//
// For each size and case (the avatar walking, turning, or standing still) the simulation is stepped
// between frames as sim_rfb does at 30 fps, and each frame is timed through:
//   render    GlRenderer::draw + glFinish (the scene itself is built outside the timer)
//   readback  OffscreenGL::read_frame (MSAA resolve where multisampled, glReadPixels, row flip)
//   damage    TileDamage::compare against the previous frame (the server does the same on its thread)
//   encode    one real libvncserver update: the frame is submitted to an in-process rfbsim::Server with
//             one libvncclient client connected; we wait until the client has the whole update and read
//             the server's stats() deltas (encode_ms, bytes_sent, tiles_changed).
// One server per JPEG quality receives the same frames, so the qualities compare like for like.
#include <GL/gl.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/simulation.hpp"
#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "render/gl_renderer.hpp"
#include "render/scene_builder.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"
#include "rfbsim/tile_damage.hpp"
#include "world/demo_world.hpp"

namespace {

namespace bench = rfbsim::bench;
namespace sim = rfbsim::sim;
using bench::Clock;

// sim_rfb's defaults: 60 Hz ticks, 30 frames per second, so two ticks between frames.
constexpr int kDefaultTicksPerFrame = 2;
// How long one update may take before the run is declared broken.
constexpr auto kUpdateTimeout = std::chrono::seconds(10);

struct Options {
  int frames = 120;
  int warmup = 10;
  int ticks_per_frame = kDefaultTicksPerFrame;
  std::vector<bench::Size> sizes{{1280, 720}, {640, 480}};
  std::vector<std::string> cases{"walk", "turn", "idle"};
  std::vector<int> qualities{80, 95};
  std::string egl_platform = "auto";
};

Options parse_options(int argc, char** argv) {
  Options o;
  bench::CommandLine cli("bench_frame",
                         "Times render, read-back, tile damage and one real libvncserver update per frame of the demo "
                         "world.\nThe first quality is the one the end-to-end frames/s uses.");
  cli.number("--frames", o.frames, 1, 1000000, "frames measured per case");
  cli.number("--warmup", o.warmup, 1, 100000, "frames run before measuring");
  cli.number("--ticks-per-frame", o.ticks_per_frame, 1, 1000, "simulation ticks between frames");
  cli.list("--sizes", o.sizes, [](const std::string& item) { return bench::parse_sizes(item).at(0); },
           "frame sizes, WxH each");
  cli.list("--cases", o.cases, bench::item_of({"walk", "turn", "idle"}, "--cases"),
           "what the avatar does: walk, turn, idle");
  cli.list("--quality", o.qualities, bench::int_in(1, 100, "--quality"), "JPEG qualities");
  bench::one_of(cli.text("--egl-platform", o.egl_platform, "EGL platform"), {"auto", "device", "surfaceless"});
  cli.parse(argc, argv);
  return o;
}

// Waits (polling) until `done` holds; throws naming `what` after kUpdateTimeout.
template <typename Predicate>
void wait_until(Predicate done, const char* what) {
  const auto deadline = Clock::now() + kUpdateTimeout;
  while (!done()) {
    if (Clock::now() > deadline) throw std::runtime_error(std::string("timed out waiting for ") + what);
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

// One in-process server at a fixed JPEG quality with one real libvncclient client watching it.
// The client is declared first so that the server goes first: it closes the connection cleanly instead
// of logging the client's disconnect as a read error.
struct Encoder {
  int quality = 0;
  std::unique_ptr<rfbsim::test::RfbTestClient> client;
  std::unique_ptr<rfbsim::Server> server;
};

Encoder make_encoder(const bench::Size& size, int quality) {
  Encoder e;
  e.quality = quality;
  rfbsim::ServerOptions options;
  options.width = size.width;
  options.height = size.height;
  options.jpeg_quality = quality;  // subsampling stays at the default 4:2:0, as sim_rfb serves
  e.server = std::make_unique<rfbsim::Server>(std::move(options));
  e.client = std::make_unique<rfbsim::test::RfbTestClient>("127.0.0.1", e.server->port());
  // The first update is the whole (grey) framebuffer; take it before measuring anything.
  if (!e.client->wait_for_updates(1, kUpdateTimeout)) throw std::runtime_error("no first update from the server");
  return e;
}

struct EncodeSample {
  bool sent = false;          // false when the frame changed no tile (the server sends nothing)
  double encode_ms = 0.0;     // server time encoding and writing the update
  double kib = 0.0;           // RFB bytes of the update / 1024
  std::uint64_t tiles = 0;    // tiles the server copied
  std::uint64_t updates = 0;  // updates the server counted for it (1 expected)
};

// Submits one frame and waits until the client holds the update it causes; returns the server's deltas.
EncodeSample encode_one(Encoder& e, const rfbsim::FrameView& frame) {
  const rfbsim::ServerStats before = e.server->stats();
  e.server->submit(frame);
  wait_until([&] { return e.server->stats().frames_applied > before.frames_applied; }, "the server to take the frame");
  EncodeSample sample;
  sample.tiles = e.server->stats().tiles_changed - before.tiles_changed;
  if (sample.tiles == 0) return sample;
  // The client requested the next update when it finished the last one, so exactly one update follows.
  if (!e.client->wait_for_updates(1, kUpdateTimeout)) throw std::runtime_error("the client got no update");
  // The server counts an update after its last write, which can be just after the client has read it.
  wait_until([&] { return e.server->stats().updates_sent > before.updates_sent; }, "the server's update count");
  const rfbsim::ServerStats after = e.server->stats();
  sample.sent = true;
  sample.updates = after.updates_sent - before.updates_sent;
  sample.encode_ms = after.encode_ms - before.encode_ms;
  sample.kib = static_cast<double>(after.bytes_sent - before.bytes_sent) / 1024.0;
  return sample;
}

// The keys a case holds; the walk turns back into a backward walk near the far wall so it never stalls.
void start_case(sim::Simulation& simulation, const std::string& name) {
  if (name == "walk") simulation.apply_key('w', true);
  if (name == "turn") simulation.apply_key('a', true);
}

void steer(sim::Simulation& simulation, const std::string& name) {
  if (name != "walk") return;
  const double y = simulation.world().avatar.pose.y;  // the demo avatar starts facing +y
  if (simulation.controls().forward && y > 2.5) {
    simulation.apply_key('w', false);
    simulation.apply_key('s', true);
  } else if (simulation.controls().backward && y < -2.5) {
    simulation.apply_key('s', false);
    simulation.apply_key('w', true);
  }
}

// Per-frame samples of one size and case.
struct CaseSamples {
  std::vector<double> scene_ms, render_ms, readback_ms, damage_ms, tiles_pct, total_ms;
  std::vector<std::vector<double>> encode_ms, kib;  // per quality
  int unsent = 0;           // frames that changed nothing
  int tile_mismatches = 0;  // frames where the server's tile count differed from ours
  int odd_updates = 0;      // sent frames the server counted as other than one update
};

// Renders, reads back, compares and encodes warmup + frames frames of one case.
CaseSamples run_case(const Options& options, const std::string& name, rfbsim::OffscreenGL& gl,
                     sim::GlRenderer& renderer, std::vector<Encoder>& encoders, std::vector<std::uint8_t>& previous,
                     std::vector<std::uint8_t>& current) {
  const int w = gl.width();
  const int h = gl.height();
  rfbsim::TileDamage damage(w, h);
  const double tile_count = damage.columns() * damage.rows();
  sim::Simulation simulation(sim::SimulationParams{}, sim::make_demo_world());
  start_case(simulation, name);

  CaseSamples s;
  s.encode_ms.resize(encoders.size());
  s.kib.resize(encoders.size());
  for (int i = 0; i < options.warmup + options.frames; ++i) {
    const bool record = i >= options.warmup;
    steer(simulation, name);
    for (int t = 0; t < options.ticks_per_frame; ++t) simulation.step();

    // Scene, render, read-back.
    gl.begin_frame();
    const auto t0 = Clock::now();
    const sim::Scene scene = sim::build_scene(simulation.world());
    const auto t1 = Clock::now();
    renderer.draw(scene, w, h);
    glFinish();
    const auto t2 = Clock::now();
    const rfbsim::FrameView frame = gl.read_frame();
    const auto t3 = Clock::now();

    // Tile damage against the previous frame (our own copies: read_frame reuses its buffer).
    for (int y = 0; y < h; ++y) {
      std::memcpy(current.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w) * 4U, frame.row(y),
                  static_cast<std::size_t>(w) * 4U);
    }
    const rfbsim::FrameView before{previous.data(), w, h, 0};
    const rfbsim::FrameView after{current.data(), w, h, 0};
    const auto t4 = Clock::now();
    const int changed = damage.compare(before, after);
    const auto t5 = Clock::now();

    // One real update per quality.
    std::vector<EncodeSample> encoded;
    for (Encoder& e : encoders) encoded.push_back(encode_one(e, after));
    previous.swap(current);
    if (!record) continue;

    s.scene_ms.push_back(bench::ms_between(t0, t1));
    s.render_ms.push_back(bench::ms_between(t1, t2));
    s.readback_ms.push_back(bench::ms_between(t2, t3));
    s.damage_ms.push_back(bench::ms_between(t4, t5));
    s.tiles_pct.push_back(100.0 * changed / tile_count);
    if (!encoded.front().sent) ++s.unsent;
    if (encoded.front().tiles != static_cast<std::uint64_t>(changed)) ++s.tile_mismatches;
    for (const EncodeSample& e : encoded) {
      if (e.sent && e.updates != 1) ++s.odd_updates;
    }
    for (std::size_t q = 0; q < encoders.size(); ++q) {
      if (!encoded[q].sent) continue;
      s.encode_ms[q].push_back(encoded[q].encode_ms);
      s.kib[q].push_back(encoded[q].kib);
    }
    s.total_ms.push_back(bench::ms_between(t0, t3) + bench::ms_between(t4, t5) + encoded.front().encode_ms);
  }
  return s;
}

int run(const Options& options) {
  // Table headings: the fixed stages, then encode time and size per quality, then frames/s.
  std::vector<std::string> headings{"size", "case", "render ms", "readback ms", "damage ms", "tiles %"};
  for (int q : options.qualities) {
    headings.push_back("encode ms q" + std::to_string(q));
    headings.push_back("KiB/update q" + std::to_string(q));
  }
  headings.push_back("e2e fps");
  bench::Table table(headings);

  const std::string load_at_start = bench::load_average();
  std::string renderer_name;
  std::vector<double> scene_ms;
  int unsent = 0;
  int mismatches = 0;
  int odd_updates = 0;
  const auto started = Clock::now();
  for (const bench::Size& size : options.sizes) {
    rfbsim::OffscreenGLOptions gl_options;
    gl_options.width = size.width;
    gl_options.height = size.height;
    gl_options.platform = options.egl_platform;  // MSAA stays at the default, as in sim_rfb
    rfbsim::OffscreenGL gl(gl_options);
    sim::GlRenderer renderer;
    renderer_name = gl.renderer();
    std::vector<Encoder> encoders;
    for (int q : options.qualities) encoders.push_back(make_encoder(size, q));
    const std::size_t bytes = static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height) * 4U;
    std::vector<std::uint8_t> previous(bytes, 0);
    std::vector<std::uint8_t> current(bytes, 0);

    for (const std::string& name : options.cases) {
      const CaseSamples s = run_case(options, name, gl, renderer, encoders, previous, current);
      scene_ms.insert(scene_ms.end(), s.scene_ms.begin(), s.scene_ms.end());
      unsent += s.unsent;
      mismatches += s.tile_mismatches;
      odd_updates += s.odd_updates;
      std::vector<std::string> row{size.text(),
                                   name,
                                   bench::p50_p90(bench::summarize(s.render_ms)),
                                   bench::p50_p90(bench::summarize(s.readback_ms)),
                                   bench::p50_p90(bench::summarize(s.damage_ms)),
                                   bench::p50_p90(bench::summarize(s.tiles_pct), 0)};
      for (std::size_t q = 0; q < encoders.size(); ++q) {
        row.push_back(bench::p50_p90(bench::summarize(s.encode_ms[q])));
        row.push_back(bench::p50_p90(bench::summarize(s.kib[q]), 1));
      }
      row.push_back(bench::fixed(1000.0 / bench::summarize(s.total_ms).p50, 1));
      table.add_row(std::move(row));
    }
  }

  std::printf("bench_frame: %s; CPU %s; load average %s at start\n", renderer_name.c_str(),
              bench::cpu_description().c_str(), load_at_start.c_str());
  std::printf("%d frames per case after %d warm-up, %d sim ticks (1/60 s) per frame; JPEG 4:2:0, 64 px tiles; "
              "cells are p50 / p90\n\n",
              options.frames, options.warmup, options.ticks_per_frame);
  table.print();
  std::printf("\nrender = GlRenderer::draw + glFinish; build_scene, not included, took p50 %.3f ms.\n",
              bench::summarize(scene_ms).p50);
  std::printf("encode = server time to encode and write one update (stats().encode_ms); KiB = RFB bytes of it.\n");
  std::printf("e2e fps = 1000 / p50(build_scene + render + readback + damage + encode q%d), one frame at a time.\n",
              options.qualities.front());
  if (unsent > 0) std::printf("%d frames changed no tile: no update, not in the encode columns.\n", unsent);
  if (mismatches > 0) std::printf("warning: %d frames where the server's changed tiles differ from ours.\n", mismatches);
  if (odd_updates > 0) std::printf("warning: %d updates where stats().updates_sent rose by other than 1.\n", odd_updates);
  std::printf("total run time %.1f s\n", bench::ms_between(started, Clock::now()) / 1000.0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse_options(argc, argv));
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "bench_frame: %s (--help shows the usage)\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_frame: error: %s\n", error.what());
    return 1;
  }
}
