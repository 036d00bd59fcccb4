// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb: one participant's simulation, rendered off-screen and served to the browser.
//
// The main thread is the simulation thread: it owns the GL context, steps the world at a fixed rate,
// and renders at the frame rate only while someone is watching. librfbsim's own thread does the network.
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/options.hpp"
#include "app/simulation.hpp"
#include "render/gl_renderer.hpp"
#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"
#include "scenario/scenario.hpp"
#include "world/demo_world.hpp"
#include "world/fixed_step_clock.hpp"

namespace {

std::atomic<bool> g_stop{false};

void request_stop(int /*signal*/) { g_stop = true; }

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A reader that went away (sim_manager's ready pipe, a client socket) must show up as EPIPE from the
  // write, which we report, not as a signal that ends the process without a word.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, nullptr);
}

// --ready-fd must name a descriptor our parent opened for writing. Checked before we open anything:
// were it closed, the number could later be reused by one of our own sockets, and the ready line would
// go there. Throws std::runtime_error naming the problem.
void check_ready_fd(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0) {
    throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": not an open file descriptor (" +
                             std::strerror(errno) + ")");
  }
  if ((flags & O_ACCMODE) == O_RDONLY) {
    throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": open for reading only");
  }
}

// Tells the parent that the port is open: one line "ready <port>\n" on `fd`, which is then closed so that
// the parent's read sees the end. Throws std::runtime_error when the write fails (EPIPE: the parent left).
void report_ready(int fd, int port) {
  const std::string line = "ready " + std::to_string(port) + "\n";
  std::size_t written = 0;
  while (written < line.size()) {
    const auto n = ::write(fd, line.data() + written, line.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string cause = n < 0 ? std::strerror(errno) : "nothing written";
      ::close(fd);
      throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": cannot write the ready line (" + cause + ")");
    }
    written += static_cast<std::size_t>(n);
  }
  ::close(fd);
}

// The page: --web-root if given, else the one built beside this binary, else the installed one.
std::string find_web_root(const std::string& requested) {
  if (!requested.empty()) return requested;
  for (const char* candidate : {RFBSIM_BUILD_WEB_ROOT, RFBSIM_INSTALLED_WEB_ROOT}) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(std::filesystem::path(candidate) / "index.html", ec)) return candidate;
  }
  throw std::runtime_error(std::string("no participant page found (looked in ") + RFBSIM_BUILD_WEB_ROOT + " and " +
                           RFBSIM_INSTALLED_WEB_ROOT + "); run 'npm ci --prefix web' and rebuild, or pass --web-root");
}

// The latest status document, written by the simulation thread and read by HTTP workers.
class StatusBoard {
 public:
  void publish(std::string text) {
    std::lock_guard lock(mutex_);
    text_ = std::move(text);
  }
  std::string read() const {
    std::lock_guard lock(mutex_);
    return text_;
  }

 private:
  mutable std::mutex mutex_;
  std::string text_ = "{}";
};

// The simulation the options ask for: a scenario with its overrides, or the built-in test room.
std::unique_ptr<rfbsim::sim::Simulation> make_simulation(const rfbsim::sim::SimOptions& options) {
  namespace sim = rfbsim::sim;
  sim::SimulationParams params;
  params.dt = 1.0 / options.tick_hz;
  if (options.scenario.empty()) {
    return std::make_unique<sim::Simulation>(params, sim::make_demo_world());
  }
  const auto file = sim::find_scenario(options.scenario, {RFBSIM_SOURCE_SCENARIOS, RFBSIM_INSTALLED_SCENARIOS});
  sim::Scenario scenario = sim::load_scenario(file);
  sim::ScenarioOverrides overrides;
  overrides.avatar_start = options.avatar_start;
  overrides.avatar_goal = options.avatar_goal;
  overrides.robot_start = options.robot_start;
  overrides.robot_goal = options.robot_goal;
  overrides.seed = options.seed;
  overrides.crowd_count = options.crowd;
  sim::apply_overrides(scenario, overrides);
  std::fprintf(stderr, "[sim_rfb] scenario %s (%s), seed %llu, %d people\n", scenario.name.c_str(),
               file.string().c_str(), static_cast<unsigned long long>(scenario.seed), scenario.crowd.count);
  return std::make_unique<sim::Simulation>(params, sim::make_world(scenario), scenario.crowd,
                                           sim::robot_setup(scenario));
}

// The robot's state changes of the last tick, one log line each ("[robot] 12.35 s moving: ...").
void log_robot_events(const rfbsim::sim::World& world, double dt) {
  for (const rfbsim::sim::RobotEvent& event : world.robot_events) {
    std::fprintf(stderr, "[robot] %.2f s %s: %s\n", static_cast<double>(event.tick) * dt,
                 rfbsim::sim::robot_state_name(event.state), event.detail.c_str());
  }
}

int run(const rfbsim::sim::SimOptions& options) {
  using Clock = std::chrono::steady_clock;
  namespace sim = rfbsim::sim;

  if (options.ready_fd) check_ready_fd(*options.ready_fd);
  // The scenario first: a broken one ends the program before anything listens.
  const std::unique_ptr<sim::Simulation> simulation_owner = make_simulation(options);
  sim::Simulation& simulation = *simulation_owner;

  StatusBoard status;
  rfbsim::ServerOptions server_options;
  server_options.port = options.port;
  server_options.bind_address = options.bind;
  server_options.width = options.width;
  server_options.height = options.height;
  server_options.jpeg_quality = options.jpeg_quality;
  server_options.max_clients = options.max_clients;
  server_options.desktop_name = "rfbsim";
  // RFB only: no web root and no route, which librfbsim takes to mean no HTTP at all, so that a raw RFB
  // client (sim_manager's relay) is served at once instead of after the wait that tells it from a browser.
  if (!options.rfb_only) {
    server_options.web_root = find_web_root(options.web_root);
    server_options.json_routes["/status.json"] = [&status] { return status.read(); };
  }
  server_options.on_connect = [](const rfbsim::ClientInfo& c) {
    std::fprintf(stderr, "[sim_rfb] client %d connected from %s (%s)\n", c.id, c.address.c_str(),
                 c.websocket ? "websocket" : "rfb");
  };
  server_options.on_disconnect = [](const rfbsim::ClientInfo& c) {
    std::fprintf(stderr, "[sim_rfb] client %d disconnected\n", c.id);
  };
  rfbsim::Server server(std::move(server_options));

  rfbsim::OffscreenGLOptions gl_options;
  gl_options.width = options.width;
  gl_options.height = options.height;
  gl_options.platform = options.egl_platform;
  rfbsim::OffscreenGL gl(gl_options);
  sim::GlRenderer renderer;
  std::fprintf(stderr, "[sim_rfb] rendering with %s\n", gl.renderer().c_str());

  sim::FixedStepClock clock(std::chrono::nanoseconds(1'000'000'000LL / options.tick_hz));
  const auto frame_interval = std::chrono::nanoseconds(1'000'000'000LL / options.fps);
  sim::SceneStyle scene_style;
  scene_style.debug_overlay = options.debug_overlay;
  std::uint64_t frames_rendered = 0;
  std::optional<sim::Scene> last_drawn;  // the server keeps showing it; an equal scene is not drawn again
  // Draws the world and hands the frame to the server, unless it would look the same as the last one.
  const auto draw_if_changed = [&] {
    sim::Scene scene = sim::build_scene(simulation.world(), scene_style);
    if (last_drawn && sim::same_scene(scene, *last_drawn)) return;
    gl.begin_frame();
    renderer.draw(scene, gl.width(), gl.height());
    server.submit(gl.read_frame());
    ++frames_rendered;
    last_drawn = std::move(scene);
  };
  // One frame before anyone watches, so that the first update a viewer gets is the scene, not black.
  draw_if_changed();

  // Readers of /status.json never see an empty document, even before the first tick.
  status.publish(sim::status_json(simulation.world(), 0, 0));
  // The parent's line first: if it cannot be told, we are not ready, and stdout should not say we are.
  if (options.ready_fd) report_ready(*options.ready_fd, server.port());
  std::printf("sim_rfb ready: %s\n", server.url().c_str());
  std::fflush(stdout);

  auto last = Clock::now();
  auto next_frame = last;
  while (!g_stop) {
    const auto now = Clock::now();
    const int ticks = clock.advance(now - last);
    last = now;

    // Input drained now takes effect from the next tick.
    for (const rfbsim::InputEvent& event : server.poll_input()) {
      if (event.kind == rfbsim::InputEvent::Kind::Key) simulation.apply_key(event.keysym, event.down);
    }
    for (int i = 0; i < ticks; ++i) {
      simulation.step();
      log_robot_events(simulation.world(), simulation.params().dt);
    }
    const int clients = server.client_count();
    if (ticks > 0 && !options.rfb_only) {
      status.publish(sim::status_json(simulation.world(), clients, frames_rendered));
    }

    // Render only for a viewer, at the frame rate.
    if (clients == 0) {
      next_frame = now;
    } else if (now >= next_frame) {
      draw_if_changed();
      next_frame += frame_interval;
      if (next_frame < now) next_frame = now + frame_interval;  // fell behind: skip, do not burst
    }
    auto wake = now + clock.until_next_step();
    if (clients > 0) wake = std::min(wake, next_frame);
    std::this_thread::sleep_until(wake);
  }
  std::fprintf(stderr, "[sim_rfb] stopping after %llu ticks, %llu frames\n",
               static_cast<unsigned long long>(simulation.world().tick),
               static_cast<unsigned long long>(frames_rendered));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  const auto parsed = rfbsim::sim::parse_sim_options(args);
  if (!parsed.error.empty()) {
    std::fprintf(stderr, "sim_rfb: %s\n%s", parsed.error.c_str(), rfbsim::sim::sim_usage().c_str());
    return 2;
  }
  if (parsed.options.help) {
    std::fputs(rfbsim::sim::sim_usage().c_str(), stdout);
    return 0;
  }
  install_signal_handlers();
  try {
    return run(parsed.options);
  } catch (const rfbsim::sim::ScenarioError& error) {
    std::fprintf(stderr, "sim_rfb: scenario error: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "sim_rfb: error: %s\n", error.what());
    return 1;
  }
}
