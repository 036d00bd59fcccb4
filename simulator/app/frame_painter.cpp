// SPDX-License-Identifier: GPL-2.0-or-later
// FramePainter: scene, then HUD.
#include "app/frame_painter.hpp"

#include <algorithm>

namespace rfbsim::sim {

namespace {

constexpr std::uint32_t kPlain = 0xffffff;
constexpr std::uint32_t kMuted = 0xc8ced6;
constexpr std::uint32_t kHighlight = 0xffd34d;  // progress and the code: what the participant looks for

}  // namespace

Hud hud_for(const TaskText& text) {
  Hud hud;
  if (!text.corner.empty()) {
    HudPanel corner;
    corner.anchor = HudAnchor::TopLeft;
    for (std::size_t i = 0; i < text.corner.size(); ++i) {
      HudLine line{text.corner[i]};
      if (i == 0) line.rgb = kMuted;                   // "Task 2 of 3"
      if (i == 1) line.scale = 1.25f;                  // the instruction
      if (i == 2 && text.corner.size() == 4) line.rgb = kHighlight;  // progress, when the step has one
      corner.lines.push_back(line);
    }
    hud.panels.push_back(corner);
  }
  if (!text.centre.empty()) {
    HudPanel centre;
    centre.anchor = HudAnchor::Center;
    for (std::size_t i = 0; i < text.centre.size(); ++i) {
      HudLine line{text.centre[i]};
      if (i == 0) line.scale = 1.5f;
      if (i == 2) {  // the code itself: large, so that it survives JPEG and can be copied by eye
        line.scale = 2.0f;
        line.rgb = kHighlight;
      }
      centre.lines.push_back(line);
    }
    hud.panels.push_back(centre);
  }
  return hud;
}

namespace {

// The HUD keeps its share of the picture: 22 px text in a 720-line frame, never under 12 px (legible after
// JPEG), so that a small frame is not half covered by its panels.
int hud_body_pixels(int frame_height) { return std::max(12, frame_height * 22 / 720); }

}  // namespace

FramePainter::FramePainter(rfbsim::OffscreenGL& gl, SceneStyle style)
    : gl_(gl), style_(style), hud_raster_(hud_font_path(), hud_body_pixels(gl.height())) {}

bool FramePainter::paint(const World& world, const TaskText& text, bool always) {
  Scene scene = build_scene(world, style_);
  Hud hud = hud_for(text);
  if (!always && last_scene_ && same_scene(scene, *last_scene_) && last_hud_ && hud == *last_hud_) return false;
  gl_.begin_frame();
  renderer_.draw(scene, gl_.width(), gl_.height());
  hud_layer_.draw(hud_raster_.layout(hud, gl_.width(), gl_.height()), gl_.width(), gl_.height());
  last_scene_ = std::move(scene);
  last_hud_ = std::move(hud);
  return true;
}

}  // namespace rfbsim::sim
