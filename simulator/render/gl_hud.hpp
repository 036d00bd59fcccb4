// SPDX-License-Identifier: GPL-2.0-or-later
// GlHudLayer: draws the HUD's placed images (render/hud.hpp) over the current framebuffer with OpenGL 3.3
// core. Like GlRenderer, it needs a current context (rfbsim::OffscreenGL) on the calling thread for its life.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "render/hud.hpp"

namespace rfbsim::sim {

/// Blends images over whatever is in the bound framebuffer, one texel per pixel. Call it after
/// GlRenderer::draw and before OffscreenGL::read_frame (see the usage in render/hud.hpp).
/// Owns one shader program, one vertex array and a texture per image.
class GlHudLayer {
 public:
  /// Compiles the shader. Throws std::runtime_error with the compiler log.
  GlHudLayer();
  ~GlHudLayer();
  GlHudLayer(const GlHudLayer&) = delete;
  GlHudLayer& operator=(const GlHudLayer&) = delete;

  /// Blends each image (straight alpha) at its place in a frame of `frame_width` x `frame_height` pixels,
  /// y counted down from the top; parts outside the frame are clipped. Textures are uploaded only when an
  /// image differs from the one drawn last in its slot. Leaves the GL state as it found it (blend, depth
  /// test, depth mask, face culling, scissor test, viewport, program, vertex array, texture binding, unpack
  /// alignment). Draws nothing,
  /// and makes no GL call, for an empty list.
  void draw(const std::vector<PlacedHudImage>& images, int frame_width, int frame_height);
  /// Texture uploads made since construction: lets tests see that an unchanged HUD costs none.
  [[nodiscard]] std::size_t uploads() const { return uploads_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t uploads_ = 0;
};

}  // namespace rfbsim::sim
