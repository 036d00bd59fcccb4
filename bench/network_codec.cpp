// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's codec comparison (see network_codec.hpp).
#include "network_codec.hpp"

#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <thread>

#include "app/simulation.hpp"
#include "h264_rfb_client.hpp"
#include "network_clients.hpp"
#include "network_report.hpp"
#include "render/gl_renderer.hpp"
#include "render/scene_builder.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::bench {

namespace {

namespace sim = rfbsim::sim;
using std::chrono::milliseconds;

constexpr auto kUpdateTimeout = milliseconds(10000);
constexpr int kWarmUpFrames = 30;
constexpr int kTicksPerFrame = 2;   // 60 Hz ticks at 30 frames per second, as sim_rfb
constexpr int kTurnPeriod = 30;     // frames: D held for the first kTurnFrames of every second
constexpr int kTurnFrames = 9;      // 300 ms

// Polls `done` until it holds; throws naming `what` after kUpdateTimeout.
template <typename Predicate>
void wait_until(Predicate done, const char* what) {
  const auto deadline = Clock::now() + kUpdateTimeout;
  while (!done()) {
    if (Clock::now() > deadline) {
      throw std::runtime_error(std::string("codec comparison: timed out waiting for ") + what);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

// One in-process server with one client. The client is declared first so that the server goes first.
struct Encoder {
  std::unique_ptr<NetClient> client;
  std::unique_ptr<rfbsim::Server> server;
  std::uint64_t update_offset = 0;  // server updates_sent - client updates(), once settled
};

Encoder make_encoder(rfbsim::Codec codec) {
  Encoder e;
  rfbsim::ServerOptions options;
  options.width = 1280;
  options.height = 720;
  options.jpeg_quality = 80;
  options.adaptive_quality = false;
  options.codec = codec;
  options.frame_rate = 30;
  e.server = std::make_unique<rfbsim::Server>(std::move(options));
  e.client = connect_client(codec == rfbsim::Codec::kH264 ? ClientKind::kH264 : ClientKind::kFbur, e.server->port(),
                            kUpdateTimeout);
  // Take whatever the server sends before the first frame (the empty framebuffer, perhaps in more than one
  // update), then pair its count with the client's.
  const auto quiet_until = Clock::now() + milliseconds(500);
  while (Clock::now() < quiet_until) e.client->pump_until([] { return false; }, milliseconds(20));
  e.update_offset = e.server->stats().updates_sent - e.client->updates();
  return e;
}

// Submits `frame` and waits until the client holds the server's update of it; false when the frame changed
// no tile (no update). Adds the update's bytes and encode time to `samples`.
bool encode_one(Encoder& e, const rfbsim::FrameView& frame, CodecSamples& samples) {
  const rfbsim::ServerStats before = e.server->stats();
  e.server->submit(frame);
  wait_until([&] { return e.server->stats().frames_applied > before.frames_applied; }, "the server to take a frame");
  if (e.server->stats().tiles_changed == before.tiles_changed) return false;
  // Pump the client meanwhile: a Tight client asks for the next update only once it has read the last one.
  const auto deadline = Clock::now() + kUpdateTimeout;
  const auto caught_up = [&] {
    const std::uint64_t sent = e.server->stats().updates_sent;
    return sent > before.updates_sent && e.client->updates() + e.update_offset >= sent;
  };
  while (!caught_up()) {
    e.client->pump_until(caught_up, milliseconds(2));
    if (!e.client->connected() || Clock::now() > deadline) {
      throw std::runtime_error("codec comparison: no update for a frame that changed tiles");
    }
  }
  const rfbsim::ServerStats after = e.server->stats();
  samples.kbytes.push_back(static_cast<double>(after.bytes_sent - before.bytes_sent) / 1000.0);
  samples.encode_ms.push_back(after.encode_ms - before.encode_ms);
  samples.ssim.push_back(luma_ssim(e.client->frame(), frame));
  return true;
}

}  // namespace

struct WalkScene::Impl {
  explicit Impl(sim::Scenario scenario)
      : simulation(sim::SimulationParams{}, sim::make_world(scenario), scenario.crowd, sim::robot_setup(scenario)),
        gl(gl_options()) {}
  static rfbsim::OffscreenGLOptions gl_options() {
    rfbsim::OffscreenGLOptions options;
    options.width = 1280;
    options.height = 720;
    return options;
  }
  sim::Simulation simulation;
  rfbsim::OffscreenGL gl;
  sim::GlRenderer renderer;  // after gl: needs its context
  int frame = 0;
};

namespace {

sim::Scenario walk_scenario(const SimSettings& settings, const std::string& source_dir) {
  sim::Scenario scenario =
      sim::load_scenario(sim::find_scenario(settings.scenario, {std::filesystem::path(source_dir) / "scenarios"}));
  sim::ScenarioOverrides overrides;
  overrides.seed = settings.seed;
  if (!settings.avatar_start.empty()) overrides.avatar_start = settings.avatar_start;
  sim::apply_overrides(scenario, overrides);
  return scenario;
}

}  // namespace

WalkScene::WalkScene(const SimSettings& settings, const std::string& source_dir)
    : impl_(std::make_unique<Impl>(walk_scenario(settings, source_dir))) {
  impl_->simulation.apply_key('w', true);
}

WalkScene::~WalkScene() = default;

FrameView WalkScene::next() {
  Impl& w = *impl_;
  w.simulation.apply_key('d', w.frame % kTurnPeriod < kTurnFrames);
  ++w.frame;
  for (int t = 0; t < kTicksPerFrame; ++t) w.simulation.step();
  w.gl.begin_frame();
  w.renderer.draw(sim::build_scene(w.simulation.world()), w.gl.width(), w.gl.height());
  glFinish();
  return w.gl.read_frame();
}

std::string WalkScene::renderer() const { return impl_->gl.renderer(); }

CodecComparison compare_codecs(const SimSettings& settings, const std::string& source_dir, int frames) {
  CodecComparison out;
  std::fprintf(stderr, "bench_network: codec comparison, %d frames ...\n", frames);
  try {
    WalkScene scene(settings, source_dir);
    out.renderer = scene.renderer();
    std::vector<Encoder> encoders;
    encoders.push_back(make_encoder(rfbsim::Codec::kH264));
    encoders.push_back(make_encoder(rfbsim::Codec::kJpeg));
    out.codecs = {CodecSamples{"h264", {}, {}, {}}, CodecSamples{"jpeg q80", {}, {}, {}}};
    CodecSamples discard;
    for (int i = 0; i < kWarmUpFrames + frames; ++i) {
      const rfbsim::FrameView frame = scene.next();
      const bool measured = i >= kWarmUpFrames;
      bool sent = false;
      for (std::size_t c = 0; c < encoders.size(); ++c) {
        sent = encode_one(encoders[c], frame, measured ? out.codecs[c] : discard) || sent;
      }
      if (measured) {
        ++out.frames;
        if (!sent) ++out.skipped;
      }
    }
  } catch (const std::exception& error) {
    out.error = error.what();
  }
  return out;
}

void print_codec_comparison(const CodecComparison& comparison) {
  if (!comparison.error.empty()) {
    std::printf("codec comparison failed: %s\n", comparison.error.c_str());
    return;
  }
  Table table({"codec", "updates", "kB/update p50", "kB/update mean", "Mbit/s at 30 fps", "SSIM mean", "SSIM p10",
               "SSIM min", "encode ms p50", "encode ms p90"},
              1);
  std::vector<double> mean_kb;
  std::vector<double> mean_ssim;
  for (const CodecSamples& c : comparison.codecs) {
    const Summary kb = summarize(c.kbytes);
    const Summary ssim = summarize(c.ssim);
    const Summary encode = summarize(c.encode_ms);
    double ssim_min = 1.0;
    for (double v : c.ssim) ssim_min = std::min(ssim_min, v);
    table.add_row({c.name, std::to_string(kb.n), fixed(kb.p50, 1), fixed(kb.mean, 1), fixed(kb.mean * 30 * 8 / 1000, 2),
                   fixed(ssim.mean, 4), fixed(quantile(c.ssim, 0.1), 4), fixed(ssim_min, 4), fixed(encode.p50, 2),
                   fixed(encode.p90, 2)});
    mean_kb.push_back(kb.mean);
    mean_ssim.push_back(ssim.mean);
  }
  std::printf("%d frames of the walk rendered in process with %s (no HUD), each encoded by both servers "
              "one at a time; %d changed nothing\n\n",
              comparison.frames, comparison.renderer.c_str(), comparison.skipped);
  table.print();
  if (mean_kb.size() == 2 && mean_kb[1] > 0) {
    std::printf("\nH.264 / JPEG q80: bytes per frame %.3f (target <= 0.333), SSIM %+.4f (target >= 0)\n",
                mean_kb[0] / mean_kb[1], mean_ssim[0] - mean_ssim[1]);
  }
}

}  // namespace rfbsim::bench
