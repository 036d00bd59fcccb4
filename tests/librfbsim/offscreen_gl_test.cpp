// SPDX-License-Identifier: GPL-2.0-or-later
// OffscreenGL: an EGL context with no window, its MSAA choices and profiles, and frames read back top row
// first, from its own framebuffer or from one the caller made. Run in rfbsim_unit_tests (tests/CMakeLists.txt).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

#include <catch2/catch.hpp>

#include "rfbsim/offscreen_gl.hpp"

namespace {
std::array<int, 4> pixel(const rfbsim::FrameView& f, int x, int y) {
  const std::uint8_t* p = f.row(y) + x * 4;
  return {p[0], p[1], p[2], p[3]};
}
}  // namespace

TEST_CASE("EGL draws a known colour at a known pixel - top row first") {
  rfbsim::OffscreenGLOptions options;
  options.width = 64;
  options.height = 32;
  rfbsim::OffscreenGL gl(options);
  INFO(gl.renderer());
  gl.begin_frame();
  glClearColor(0.0f, 0.0f, 1.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  // A red block in GL's bottom-left 8x4 pixels must come out at the bottom-left of the top-down frame.
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, 8, 4);
  glClearColor(1.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
  const rfbsim::FrameView frame = gl.read_frame();
  REQUIRE(frame.width == 64);
  REQUIRE(frame.height == 32);
  CHECK(pixel(frame, 0, 31) == std::array<int, 4>{255, 0, 0, 255});
  CHECK(pixel(frame, 7, 28) == std::array<int, 4>{255, 0, 0, 255});
  CHECK(pixel(frame, 8, 31) == std::array<int, 4>{0, 0, 255, 255});
  CHECK(pixel(frame, 0, 27) == std::array<int, 4>{0, 0, 255, 255});
  CHECK(pixel(frame, 0, 0) == std::array<int, 4>{0, 0, 255, 255});
}

TEST_CASE("two contexts share the process's display and bad sizes are refused") {
  rfbsim::OffscreenGL a({16, 16, 0, "auto"});
  rfbsim::OffscreenGL b({16, 16, 4, "auto"});
  b.begin_frame();
  glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  CHECK(pixel(b.read_frame(), 8, 8) == std::array<int, 4>{0, 255, 0, 255});
  CHECK_THROWS_AS(rfbsim::OffscreenGL({0, 16, 0, "auto"}), std::runtime_error);
}

TEST_CASE("automatic MSAA is off on a software rasterizer and 4x on a GPU") {
  rfbsim::OffscreenGL automatic({64, 64, rfbsim::OffscreenGLOptions::kAutoSamples, "auto"});
  const std::string name = automatic.renderer();
  const bool software = name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos;
  INFO(name);
  CHECK(automatic.samples() == (software ? 0 : 4));
}

TEST_CASE("an explicit MSAA count is kept, and a count of 1 is no MSAA") {
  CHECK(rfbsim::OffscreenGL({64, 64, 4, "auto"}).samples() == 4);
  CHECK(rfbsim::OffscreenGL({64, 64, 1, "auto"}).samples() == 0);
}

TEST_CASE("an MSAA count beyond the renderer's most gets its most") {
  // More than the renderer can do is its most, not a broken framebuffer.
  rfbsim::OffscreenGL greedy({64, 64, 1024, "auto"});
  GLint most = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &most);
  CHECK(greedy.samples() == (most > 1 ? most : 0));
}

TEST_CASE("without multisampling the picture is read straight from the drawing framebuffer") {
  rfbsim::OffscreenGL plain({64, 64, 0, "auto"});
  REQUIRE(plain.samples() == 0);
  plain.begin_frame();
  glClearColor(1.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 60, 4, 4);  // GL's top rows: the frame's first rows
  glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
  const rfbsim::FrameView frame = plain.read_frame();
  CHECK(pixel(frame, 1, 1) == std::array<int, 4>{0, 255, 0, 255});
  CHECK(pixel(frame, 3, 60) == std::array<int, 4>{255, 0, 0, 255});
}

TEST_CASE("a compatibility-profile context draws with fixed-function GL, as MuJoCo 2.x's renderer does") {
  rfbsim::OffscreenGLOptions options;
  options.width = 32;
  options.height = 32;
  options.samples = 0;
  options.profile = rfbsim::GLProfile::kCompatibility;
  rfbsim::OffscreenGL gl(options);
  INFO(gl.renderer());
  CHECK(gl.profile() == rfbsim::GLProfile::kCompatibility);
  gl.begin_frame();
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  // glBegin/glEnd and the fixed matrices exist only outside the core profile: a green quad over the left half.
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, 32, 0, 32, -1, 1);
  glColor3f(0.0f, 1.0f, 0.0f);
  glBegin(GL_QUADS);
  glVertex2f(0, 0);
  glVertex2f(16, 0);
  glVertex2f(16, 32);
  glVertex2f(0, 32);
  glEnd();
  REQUIRE(glGetError() == GL_NO_ERROR);
  const rfbsim::FrameView frame = gl.read_frame();
  CHECK(pixel(frame, 4, 4) == std::array<int, 4>{0, 255, 0, 255});
  CHECK(pixel(frame, 28, 4) == std::array<int, 4>{0, 0, 0, 255});
  // The default stays 3.3 core.
  CHECK(rfbsim::OffscreenGL({16, 16, 0, "auto"}).profile() == rfbsim::GLProfile::kCore33);
}

TEST_CASE("read_framebuffer reads a framebuffer the caller made, top row first, and refuses what it cannot read") {
  for (const int samples : {0, 4}) {
    rfbsim::OffscreenGL gl({48, 32, 0, "auto", rfbsim::GLProfile::kCompatibility});
    gl.begin_frame();
    // The caller's own FBO (as MuJoCo's mjrContext makes one): a blue picture with a red bottom-left block.
    GLuint colour = 0;
    GLuint fbo = 0;
    glGenRenderbuffers(1, &colour);
    glBindRenderbuffer(GL_RENDERBUFFER, colour);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, 48, 32);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glClearColor(0.0f, 0.0f, 1.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);  // left on, as renderers leave it: the read must still copy the whole picture
    glScissor(0, 0, 8, 4);
    glClearColor(1.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    INFO("samples " << samples);
    const rfbsim::FrameView frame = gl.read_framebuffer(fbo);
    CHECK(frame.width == 48);
    CHECK(frame.height == 32);
    CHECK(pixel(frame, 0, 31) == std::array<int, 4>{255, 0, 0, 255});
    CHECK(pixel(frame, 8, 31) == std::array<int, 4>{0, 0, 255, 255});
    CHECK(pixel(frame, 47, 0) == std::array<int, 4>{0, 0, 255, 255});
    GLint bound = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &bound);
    CHECK(bound == static_cast<GLint>(fbo));  // left as the caller had it
    CHECK(glIsEnabled(GL_SCISSOR_TEST) == GL_TRUE);
    glDisable(GL_SCISSOR_TEST);

    // Not a framebuffer, the default one, and one smaller than the context: clear errors, no crash.
    CHECK_THROWS_WITH(gl.read_framebuffer(fbo + 1000), Catch::Contains("not a framebuffer object"));
    CHECK_THROWS_WITH(gl.read_framebuffer(0), Catch::Contains("not a framebuffer object"));
    glBindRenderbuffer(GL_RENDERBUFFER, colour);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, 16, 16);
    CHECK_THROWS_WITH(gl.read_framebuffer(fbo), Catch::Contains("16x16, smaller than the context's 48x32"));
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &colour);
  }
}
