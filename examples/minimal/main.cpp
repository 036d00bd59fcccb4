// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_minimal: serve an animated OpenGL scene to VNC and noVNC clients in about 100 lines.
//
//   rfbsim_minimal [PORT]      then connect a VNC viewer to 127.0.0.1:PORT (default 5902),
//                              or any noVNC page to ws://127.0.0.1:PORT/
// Space toggles the animation; every other key and the pointer are printed.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <rfbsim/offscreen_gl.hpp>
#include <rfbsim/server.hpp>

namespace {

std::atomic<bool> stop{false};

// Draws one frame with nothing but scissored clears: a sky, a floor, and a square sliding over it.
void draw(int width, int height, double t) {
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, width, height);
  glClearColor(0.55f, 0.7f, 0.85f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glScissor(0, 0, width, height / 3);
  glClearColor(0.45f, 0.42f, 0.38f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  const int size = height / 5;
  const int x = static_cast<int>((0.5 + 0.4 * std::sin(t)) * (width - size));
  glScissor(x, height / 3 - size / 4, size, size);
  glClearColor(0.9f, 0.35f, 0.2f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
}

}  // namespace

int main(int argc, char** argv) {
  // The command line: one optional argument, declared once (CLI11 gives --help and the errors from it).
  CLI::App app("Serves an animated OpenGL scene to VNC and noVNC clients", "rfbsim_minimal");
  int port = 5902;
  app.add_option("PORT", port, "TCP port; 0 = any free one")->capture_default_str()->check(CLI::Range(0, 65535));
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, [](int) { stop = true; });
  std::signal(SIGTERM, [](int) { stop = true; });
  try {
    rfbsim::ServerOptions options;
    options.port = port;
    options.width = 640;
    options.height = 480;
    options.on_connect = [](const rfbsim::ClientInfo& c) { std::printf("client %d connected\n", c.id); };
    rfbsim::Server server(options);

    rfbsim::OffscreenGLOptions gl_options;
    gl_options.width = options.width;
    gl_options.height = options.height;
    rfbsim::OffscreenGL gl(gl_options);
    std::printf("serving %s on %s\n", gl.renderer().c_str(), server.url().c_str());
    std::fflush(stdout);

    bool animate = true;
    double t = 0.0;
    const auto frame = std::chrono::milliseconds(33);
    auto next = std::chrono::steady_clock::now();
    while (!stop) {
      // Input: keys and pointer arrive as timestamped events.
      for (const rfbsim::InputEvent& e : server.poll_input()) {
        if (e.kind == rfbsim::InputEvent::Kind::Key && e.down && e.keysym == ' ') animate = !animate;
        if (e.kind == rfbsim::InputEvent::Kind::Key) {
          std::printf("key 0x%x %s\n", e.keysym, e.down ? "down" : "up");
        } else if (e.buttons != 0) {
          std::printf("pointer %d,%d buttons %u\n", e.x, e.y, e.buttons);
        }
      }
      if (animate) t += 1.0 / 30.0;
      // Render only while someone watches; the server sends only the tiles that changed.
      if (server.client_count() > 0) {
        gl.begin_frame();
        draw(gl.width(), gl.height(), t);
        server.submit(gl.read_frame());
      }
      next += frame;
      std::this_thread::sleep_until(next);
    }
    const rfbsim::ServerStats stats = server.stats();
    std::printf("frames %llu, updates %llu, bytes %llu\n", static_cast<unsigned long long>(stats.frames_submitted),
                static_cast<unsigned long long>(stats.updates_sent), static_cast<unsigned long long>(stats.bytes_sent));
  } catch (const std::exception& error) {
    std::fprintf(stderr, "rfbsim_minimal: %s\n", error.what());
    return 1;
  }
  return 0;
}
