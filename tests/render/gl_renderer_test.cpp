// SPDX-License-Identifier: GPL-2.0-or-later
// GlRenderer: the demo world's scene drawn into an OffscreenGL frame (Mesa llvmpipe needs no GPU).
#include "render/gl_renderer.hpp"

#include <array>
#include <catch2/catch.hpp>
#include <cstdint>

#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "world/demo_world.hpp"

namespace {
// The RGBA bytes of pixel (x, y), the frame's top row being y = 0.
std::array<int, 4> rgba_at(const rfbsim::FrameView& f, int x, int y) {
  const std::uint8_t* p = f.row(y) + x * 4;
  return {p[0], p[1], p[2], p[3]};
}
}  // namespace

TEST_CASE("the demo scene renders sky above and the avatar's blue shirt at the centre") {
  rfbsim::OffscreenGL gl({320, 240, 4, "auto"});
  rfbsim::sim::GlRenderer renderer;
  const auto world = rfbsim::sim::make_demo_world();
  gl.begin_frame();
  renderer.draw(rfbsim::sim::build_scene(world), 320, 240);
  const auto frame = gl.read_frame();
  // The avatar stands in front of the camera, so the centre column shows its shirt (0x2f7fd0, lit):
  // blue dominates red there.
  bool shirt = false;
  for (int y = 100; y < 200 && !shirt; ++y) {
    const auto p = rgba_at(frame, 160, y);
    shirt = p[2] > p[0] + 60;
  }
  CHECK(shirt);
  CHECK(renderer.last_triangles() > 100);
}
