// SPDX-License-Identifier: GPL-2.0-or-later
// mujoco_rfb: a MuJoCo model in the browser through librfbsim. MuJoCo steps the physics in real time and
// draws with its own renderer (mjr_*) into its offscreen framebuffer, on the compatibility-profile EGL
// context that rfbsim::OffscreenGL makes; librfbsim reads that framebuffer and serves it over RFB and
// WebSocket, and hands back the viewer's keys (actuator targets) and pointer (camera).
//
//   mujoco_rfb [--port N] [--bind ADDR] [--model FILE] ...   (--help lists them)
// It prints "mujoco_rfb ready: URL" once it serves; SIGINT or SIGTERM ends it (exit 0).
#include <mujoco/mujoco.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <rfbsim/log.hpp>
#include <rfbsim/offscreen_gl.hpp>
#include <rfbsim/server.hpp>

#include "key_controls.hpp"
#include "options.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kFramesPerSecond = 30;
constexpr int kMaxStepsPerFrame = 200;  // physics may fall behind wall time rather than spiral

std::atomic<bool> stop{false};

// The first candidate that exists, else "".
std::string first_existing(const std::vector<std::string>& candidates) {
  for (const std::string& path : candidates) {
    std::error_code error;
    if (!path.empty() && std::filesystem::exists(path, error)) return path;
  }
  return "";
}

// Whether GL_RENDERER names one of Mesa's software rasterizers, where shadows and MSAA cost too much.
bool software_renderer(const rfbsim::OffscreenGL& gl) {
  const std::string name = gl.renderer();
  return name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos;
}

// MuJoCo's models, data and renderer state, freed in the right order (the GL context must still be current).
struct Mujoco {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  mjvCamera camera{};
  mjvOption option{};
  mjvScene scene{};
  mjrContext context{};
  bool gl_made = false;  // mjr_makeContext ran: its GL objects need freeing
  ~Mujoco() {
    if (gl_made) mjr_freeContext(&context);
    mjv_freeScene(&scene);
    if (data != nullptr) mj_deleteData(data);
    if (model != nullptr) mj_deleteModel(model);
  }
};

// The pointer moves the free camera: left drag orbits, right drag pans, wheel clicks (buttons 4 and 5) zoom.
class PointerCamera {
 public:
  void apply(const rfbsim::InputEvent& e, Mujoco& mj, int height) {
    const double dx = static_cast<double>(e.x - x_) / height;
    const double dy = static_cast<double>(e.y - y_) / height;
    const std::uint8_t held = e.buttons & buttons_;  // buttons down before and now: a drag
    if ((held & 1U) != 0) mjv_moveCamera(mj.model, mjMOUSE_ROTATE_V, dx, dy, &mj.scene, &mj.camera);
    if ((held & 4U) != 0) mjv_moveCamera(mj.model, mjMOUSE_MOVE_V, dx, dy, &mj.scene, &mj.camera);
    // Wheel up (button 4) brings the camera closer: MuJoCo's zoom shortens the distance for a positive dy.
    const std::uint8_t pressed = e.buttons & ~buttons_;
    if ((pressed & 8U) != 0) mjv_moveCamera(mj.model, mjMOUSE_ZOOM, 0, 0.05, &mj.scene, &mj.camera);
    if ((pressed & 16U) != 0) mjv_moveCamera(mj.model, mjMOUSE_ZOOM, 0, -0.05, &mj.scene, &mj.camera);
    x_ = e.x;
    y_ = e.y;
    buttons_ = e.buttons;
  }

 private:
  int x_ = 0;
  int y_ = 0;
  std::uint8_t buttons_ = 0;
};

// What the picture depends on: the joint positions and the camera. Unchanged = no need to draw again.
struct ViewState {
  std::vector<mjtNum> qpos;
  mjtNum lookat[3] = {0, 0, 0};
  mjtNum distance = 0, azimuth = 0, elevation = 0;
};

// Whether `a` and `b` draw the same picture. A body at rest still jitters by far less than a pixel in the solver,
// so positions count as unchanged within 1e-5 (m or rad); redrawing that jitter cost 0.4 of a core on llvmpipe
// for a picture nobody could tell apart (bench_session_kinds).
bool looks_the_same(const ViewState& a, const ViewState& b) {
  constexpr mjtNum kUnseen = 1e-5;
  if (a.qpos.size() != b.qpos.size()) return false;
  for (std::size_t i = 0; i < a.qpos.size(); ++i) {
    if (std::fabs(a.qpos[i] - b.qpos[i]) > kUnseen) return false;
  }
  return a.lookat[0] == b.lookat[0] && a.lookat[1] == b.lookat[1] && a.lookat[2] == b.lookat[2] &&
         a.distance == b.distance && a.azimuth == b.azimuth && a.elevation == b.elevation;
}

ViewState view_state(const Mujoco& mj) {
  ViewState s;
  s.qpos.assign(mj.data->qpos, mj.data->qpos + mj.model->nq);
  for (int i = 0; i < 3; ++i) s.lookat[i] = mj.camera.lookat[i];
  s.distance = mj.camera.distance;
  s.azimuth = mj.camera.azimuth;
  s.elevation = mj.camera.elevation;
  return s;
}

int run(const mujoco_rfb::Options& options) {
  // The model: --model, else the installed one, else the one in the source tree.
  const std::string model_path = !options.model.empty()
      ? options.model
      : first_existing({MUJOCO_RFB_INSTALLED_MODEL, MUJOCO_RFB_SOURCE_MODEL});
  // Declared first, made after the model loads: MuJoCo's GL objects must go while its context still exists.
  std::optional<rfbsim::OffscreenGL> gl;
  Mujoco mj;
  char load_error[1000] = "";
  mj.model = mj_loadXML(model_path.c_str(), nullptr, load_error, sizeof load_error);
  if (mj.model == nullptr) throw std::runtime_error("cannot load the model '" + model_path + "': " + load_error);
  mj.data = mj_makeData(mj.model);

  // The GL context first: MuJoCo 2.x draws with fixed-function GL, which needs the compatibility profile.
  rfbsim::OffscreenGLOptions gl_options;
  gl_options.width = options.width;
  gl_options.height = options.height;
  gl_options.profile = rfbsim::GLProfile::kCompatibility;
  gl.emplace(gl_options);
  const bool software = software_renderer(*gl);
  // MuJoCo's offscreen buffer is the frame's size (read_framebuffer needs at least that); its MSAA is the
  // one OffscreenGL chose (none on llvmpipe), and shadows go too on llvmpipe.
  mj.model->vis.global.offwidth = options.width;
  mj.model->vis.global.offheight = options.height;
  mj.model->vis.quality.offsamples = gl->samples();
  mjv_defaultFreeCamera(mj.model, &mj.camera);
  mjv_defaultOption(&mj.option);
  mjv_defaultScene(&mj.scene);
  mjv_makeScene(mj.model, &mj.scene, 2000);
  mj.scene.flags[mjRND_SHADOW] = software ? 0 : 1;
  mjr_defaultContext(&mj.context);
  mjr_makeContext(mj.model, &mj.context, mjFONTSCALE_100);
  mj.gl_made = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &mj.context);
  if (mj.context.currentBuffer != mjFB_OFFSCREEN) throw std::runtime_error("MuJoCo has no offscreen buffer");
  const mjrRect viewport{0, 0, options.width, options.height};

  rfbsim::ServerOptions server_options;
  server_options.port = options.port;
  server_options.bind_address = options.bind;
  server_options.width = options.width;
  server_options.height = options.height;
  server_options.frame_rate = kFramesPerSecond;
  server_options.desktop_name = "mujoco_rfb: " + std::string(mj.model->names);  // the model's name comes first
  if (!options.rfb_only) {
    server_options.web_root = !options.web_root.empty()
        ? options.web_root
        : first_existing({MUJOCO_RFB_BUILD_WEB_ROOT, MUJOCO_RFB_INSTALLED_WEB_ROOT});
  }
  rfbsim::Server server(server_options);

  KeyControls keys(mj.model);
  PointerCamera pointer;
  std::optional<ViewState> drawn;  // what the last submitted frame showed
  const auto draw_if_changed = [&] {
    ViewState now = view_state(mj);
    if (drawn && looks_the_same(*drawn, now)) return;
    gl->begin_frame();
    mjv_updateScene(mj.model, mj.data, &mj.option, nullptr, &mj.camera, mjCAT_ALL, &mj.scene);
    mjr_setBuffer(mjFB_OFFSCREEN, &mj.context);
    mjr_render(viewport, &mj.scene, &mj.context);
    server.submit(gl->read_framebuffer(mj.context.offFBO));
    drawn = std::move(now);
  };
  // One frame before anyone watches, so that the first picture a viewer gets is the scene, not black.
  draw_if_changed();
  std::printf("mujoco_rfb ready: %s\n", server.url().c_str());
  std::printf("mujoco_rfb: model %s, %s, %s\n", model_path.c_str(), gl->renderer().c_str(),
              software ? "no shadows" : "shadows");
  std::fflush(stdout);

  // Real time: physics catches up with the wall clock each frame; the picture is drawn only while watched.
  const auto period = std::chrono::microseconds(1000000 / kFramesPerSecond);
  auto start = Clock::now();
  auto next = start;
  auto last = start;
  while (!stop) {
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    for (const rfbsim::InputEvent& e : server.poll_input()) {
      if (e.kind == rfbsim::InputEvent::Kind::Key) keys.key(e.keysym, e.down, mj.model, mj.data);
      else pointer.apply(e, mj, options.height);
    }
    keys.apply(dt, mj.model, mj.data);
    const double wall = std::chrono::duration<double>(now - start).count();
    int steps = 0;
    while (mj.data->time < wall && steps++ < kMaxStepsPerFrame) mj_step(mj.model, mj.data);
    if (mj.data->time < wall) start = now - std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(mj.data->time));
    if (server.client_count() > 0) draw_if_changed();
    next += period;
    if (next < Clock::now()) next = Clock::now();  // a slow frame does not make the next ones burst
    std::this_thread::sleep_until(next);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, [](int) { stop = true; });
  std::signal(SIGTERM, [](int) { stop = true; });
  const mujoco_rfb::Parsed parsed = mujoco_rfb::parse_options(argc, argv);
  if (!parsed.error.empty()) {
    std::fprintf(stderr, "mujoco_rfb: %s\n%s", parsed.error.c_str(), mujoco_rfb::usage().c_str());
    return 2;
  }
  if (parsed.options.help) {
    std::fputs(mujoco_rfb::usage().c_str(), stdout);
    return 0;
  }
  rfbsim::log::set_level(parsed.options.log_level);  // checked by the parser
  try {
    return run(parsed.options);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "mujoco_rfb: %s\n", error.what());
    return 1;
  }
}
