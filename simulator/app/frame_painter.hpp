// SPDX-License-Identifier: GPL-2.0-or-later
// FramePainter: the participant's picture of one moment: the world's scene drawn with GL, and the task's
// HUD over it. sim_rfb paints what it serves; sim_replay paints the same frames into a video.
#pragma once

#include <optional>

#include "render/draw_list.hpp"
#include "render/gl_hud.hpp"
#include "render/gl_renderer.hpp"
#include "render/hud.hpp"
#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "task/task_display.hpp"

namespace rfbsim::sim {

/// The HUD panels for the task's words: the running task in the top-left corner, the outcome and its code
/// large in the middle.
Hud hud_for(const TaskText& text);

class FramePainter {
 public:
  /// Needs `gl`'s context current on this thread, for the painter's whole life. Throws std::runtime_error
  /// when the HUD's font cannot be loaded (hud_font_path()).
  FramePainter(rfbsim::OffscreenGL& gl, SceneStyle style);

  /// Draws `world` and the HUD for `text` into `gl`'s framebuffer unless both would look as last drawn (or
  /// `always`). Returns whether it drew; the picture is then read with gl.read_frame().
  bool paint(const World& world, const TaskText& text, bool always = false);

 private:
  rfbsim::OffscreenGL& gl_;
  SceneStyle style_;
  GlRenderer renderer_;
  HudRasterizer hud_raster_;
  GlHudLayer hud_layer_;
  std::optional<Scene> last_scene_;
  std::optional<Hud> last_hud_;
};

}  // namespace rfbsim::sim
