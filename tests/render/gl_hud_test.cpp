// SPDX-License-Identifier: GPL-2.0-or-later
// GlHudLayer: panels blended into an OffscreenGL frame texel for texel, the GL state left as found, textures
// uploaded only on change; and a sample HUD over the warehouse saved as a PNG.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "hud_panels.hpp"
#include "render/gl_hud.hpp"
#include "render/gl_renderer.hpp"
#include "render/hud.hpp"
#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "scenario/scenario.hpp"

namespace {

using rfbsim::sim::GlHudLayer;
using rfbsim::sim::Hud;
using rfbsim::sim::HudAnchor;
using rfbsim::sim::HudPanel;
using rfbsim::sim::HudRasterizer;
using rfbsim::sim::PlacedHudImage;
using rfbsim::test::panel_of;

using Pixel = std::array<int, 4>;

Pixel pixel(const rfbsim::FrameView& f, int x, int y) {
  const std::uint8_t* p = f.row(y) + x * 4;
  return {p[0], p[1], p[2], p[3]};
}

// A copy of a frame, tightly packed, to compare two frames read from one context.
std::vector<std::uint8_t> copy_of(const rfbsim::FrameView& f) {
  std::vector<std::uint8_t> out;
  for (int y = 0; y < f.height; ++y) out.insert(out.end(), f.row(y), f.row(y) + f.width * 4);
  return out;
}

// What straight-alpha "over" gives on an opaque background, per channel (0..255).
Pixel over(const Pixel& top, const Pixel& under) {
  Pixel out{};
  for (std::size_t k = 0; k < 3; ++k) out[k] = (top[k] * top[3] + under[k] * (255 - top[3]) + 127) / 255;
  out[3] = 255;
  return out;
}

// The frame pixel (x, y) that the placed images would give over an opaque `background`.
Pixel expected(const std::vector<PlacedHudImage>& placed, int x, int y, const Pixel& background) {
  Pixel out = background;
  for (const auto& p : placed) {
    const int ix = x - p.x;
    const int iy = y - p.y;
    if (ix < 0 || iy < 0 || ix >= p.image.width || iy >= p.image.height) continue;
    const std::uint8_t* s = &p.image.rgba[static_cast<std::size_t>((iy * p.image.width + ix) * 4)];
    out = over({s[0], s[1], s[2], s[3]}, out);
  }
  return out;
}

// The largest difference of any channel of any pixel between the frame and the expected picture.
int worst_difference(const rfbsim::FrameView& frame, const std::vector<PlacedHudImage>& placed, const Pixel& bg) {
  int worst = 0;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const Pixel want = expected(placed, x, y, bg);
      const Pixel got = pixel(frame, x, y);
      for (std::size_t k = 0; k < 4; ++k) worst = std::max(worst, std::abs(want[k] - got[k]));
    }
  }
  return worst;
}

void clear_to_grey() {
  glClearColor(0.5f, 0.5f, 0.5f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

}  // namespace

TEST_CASE("the layer blends each panel over the frame texel for texel with the top-left panel at the top") {
  constexpr int kWidth = 400;
  constexpr int kHeight = 240;
  rfbsim::OffscreenGL gl({kWidth, kHeight, 0, "auto"});
  INFO(gl.renderer());
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  GlHudLayer layer;
  Hud hud;
  hud.panels = {panel_of({"Task 2 of 3", "Following: 12 / 30 s"}, HudAnchor::TopLeft),
                panel_of({"C1A2B3"}, HudAnchor::Center)};
  const auto placed = raster.layout(hud, kWidth, kHeight);
  REQUIRE(placed.size() == 2);

  gl.begin_frame();
  clear_to_grey();
  const Pixel grey = pixel(gl.read_frame(), 0, 0);
  gl.begin_frame();
  clear_to_grey();
  layer.draw(placed, kWidth, kHeight);
  const rfbsim::FrameView frame = gl.read_frame();

  // Every pixel: the images blended where they lie, the grey untouched everywhere else (rounding: 1 step).
  CHECK(worst_difference(frame, placed, grey) <= 1);
  // The top-left panel's background darkens the frame's top rows, not its bottom rows (no flip).
  const auto& top_left = placed[0];
  const int band_x = top_left.x + raster.style().padding / 2;
  const int band_y = top_left.y + top_left.image.height / 2;
  CHECK(pixel(frame, band_x, band_y)[0] < grey[0] - 40);
  CHECK(pixel(frame, band_x, kHeight - 1 - band_y) == grey);
  // Just outside the panel and at the frame's far corner: unchanged.
  CHECK(pixel(frame, top_left.x + top_left.image.width, band_y) == grey);
  CHECK(pixel(frame, top_left.x - 1, band_y) == grey);
  CHECK(pixel(frame, kWidth - 1, kHeight - 1) == grey);
  // Some text pixels come out pure white.
  bool white = false;
  for (int y = top_left.y; y < top_left.y + top_left.image.height && !white; ++y) {
    for (int x = top_left.x; x < top_left.x + top_left.image.width && !white; ++x) {
      white = pixel(frame, x, y) == Pixel{255, 255, 255, 255};
    }
  }
  CHECK(white);
}

TEST_CASE("the layer leaves the GL state as it found it and uploads only images that changed") {
  constexpr int kWidth = 320;
  constexpr int kHeight = 200;
  rfbsim::OffscreenGL gl({kWidth, kHeight, 0, "auto"});
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  GlHudLayer layer;
  Hud hud;
  hud.panels = {panel_of({"Time left 3:12"}, HudAnchor::TopRight)};

  gl.begin_frame();
  clear_to_grey();
  const Pixel grey = pixel(gl.read_frame(), 0, 0);
  gl.begin_frame();
  // The state a 3D renderer might leave behind.
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ZERO);
  glViewport(3, 4, 50, 60);
  layer.draw(raster.layout(hud, kWidth, kHeight), kWidth, kHeight);
  CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_TRUE);
  CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
  CHECK(glIsEnabled(GL_BLEND) == GL_FALSE);
  GLint value = -1;
  glGetIntegerv(GL_BLEND_SRC_RGB, &value);
  CHECK(value == GL_ONE);
  glGetIntegerv(GL_BLEND_DST_ALPHA, &value);
  CHECK(value == GL_ZERO);
  glGetIntegerv(GL_CURRENT_PROGRAM, &value);
  CHECK(value == 0);
  glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &value);
  CHECK(value == 0);
  std::array<GLint, 4> viewport{};
  glGetIntegerv(GL_VIEWPORT, viewport.data());
  CHECK(viewport == std::array<GLint, 4>{3, 4, 50, 60});
  CHECK(glGetError() == GL_NO_ERROR);
  CHECK(layer.uploads() == 1);

  // Frame after frame with the same HUD: no upload, the same picture.
  glViewport(0, 0, kWidth, kHeight);
  for (int frame = 0; frame < 3; ++frame) {
    gl.begin_frame();
    clear_to_grey();
    layer.draw(raster.layout(hud, kWidth, kHeight), kWidth, kHeight);
  }
  CHECK(layer.uploads() == 1);
  CHECK(worst_difference(gl.read_frame(), raster.layout(hud, kWidth, kHeight), grey) <= 1);

  // A tick of the clock: one upload, and the frame shows the new text.
  hud.panels[0].lines[0].text = "Time left 3:11";
  gl.begin_frame();
  clear_to_grey();
  layer.draw(raster.layout(hud, kWidth, kHeight), kWidth, kHeight);
  CHECK(layer.uploads() == 2);
  CHECK(worst_difference(gl.read_frame(), raster.layout(hud, kWidth, kHeight), grey) <= 1);

  // A bigger panel in the same slot, then none at all: nothing drawn, nothing uploaded.
  hud.panels[0].lines.push_back({"Following: 12 / 30 s"});
  gl.begin_frame();
  clear_to_grey();
  layer.draw(raster.layout(hud, kWidth, kHeight), kWidth, kHeight);
  CHECK(layer.uploads() == 3);
  CHECK(worst_difference(gl.read_frame(), raster.layout(hud, kWidth, kHeight), grey) <= 1);
  gl.begin_frame();
  clear_to_grey();
  layer.draw(raster.layout(Hud{}, kWidth, kHeight), kWidth, kHeight);
  CHECK(worst_difference(gl.read_frame(), {}, grey) == 0);
  CHECK(glGetError() == GL_NO_ERROR);
}

TEST_CASE("a HUD over the warehouse changes only the pixels under its panels and is saved as a PNG") {
  constexpr int kWidth = 1280;
  constexpr int kHeight = 720;
  rfbsim::OffscreenGL gl({kWidth, kHeight, 0, "auto"});
  rfbsim::sim::GlRenderer renderer;
  GlHudLayer layer;
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const auto world =
      rfbsim::sim::make_world(rfbsim::sim::load_scenario(std::filesystem::path(RFBSIM_SCENARIO_DIR) / "warehouse.yaml"));
  const auto scene = rfbsim::sim::build_scene(world);
  Hud hud;
  HudPanel task = panel_of({"Task 2 of 3: Follow the robot", "Following: 12 / 30 s", "Time left 3:12"},
                           HudAnchor::TopLeft);
  task.lines[0].scale = 1.25f;
  task.lines[1].rgb = 0xffd54a;
  HudPanel code = panel_of({"Well done!", "Your completion code: C1A2B3"}, HudAnchor::Center);
  code.lines[0].scale = 1.6f;
  hud.panels = {task, code};
  const auto placed = raster.layout(hud, kWidth, kHeight);

  gl.begin_frame();
  renderer.draw(scene, kWidth, kHeight);
  const auto plain = copy_of(gl.read_frame());
  gl.begin_frame();
  renderer.draw(scene, kWidth, kHeight);
  layer.draw(placed, kWidth, kHeight);
  const rfbsim::FrameView frame = gl.read_frame();
  const auto with_hud = copy_of(frame);

  // Outside the panels the renderer's picture is untouched; inside, most pixels are darkened or lit.
  int changed_outside = 0;
  int changed_inside = 0;
  int inside = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const bool under = std::any_of(placed.begin(), placed.end(), [&](const PlacedHudImage& p) {
        return x >= p.x && y >= p.y && x < p.x + p.image.width && y < p.y + p.image.height;
      });
      const std::size_t i = static_cast<std::size_t>((y * kWidth + x) * 4);
      const bool same = std::equal(&plain[i], &plain[i] + 4, &with_hud[i]);
      inside += under;
      changed_inside += under && !same;
      changed_outside += !under && !same;
    }
  }
  CHECK(changed_outside == 0);
  CHECK(changed_inside > inside * 9 / 10);

  // For a look at contrast and size (JPEG on the way to the browser blurs small text).
  const std::filesystem::path dir = RFBSIM_ARTIFACT_DIR;
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "hud_sample.png").string();
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = kWidth;
  png.height = kHeight;
  png.format = PNG_FORMAT_RGBA;
  CHECK(png_image_write_to_file(&png, file.c_str(), 0, frame.pixels, static_cast<png_int_32>(frame.row_bytes()),
                                nullptr) != 0);
  CHECK(std::filesystem::file_size(file) > 10000);
}
