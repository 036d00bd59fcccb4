// SPDX-License-Identifier: GPL-2.0-or-later
// GlRenderer: draws a Scene with OpenGL 3.3 core into the current framebuffer. The only GL user in the
// simulator; it needs a current context (rfbsim::OffscreenGL) on the calling thread for its whole life.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "render/draw_list.hpp"

namespace rfbsim::sim {

class GlRenderer {
 public:
  /// Compiles the shaders and uploads the unit meshes. Throws std::runtime_error with the compiler log.
  GlRenderer();
  ~GlRenderer();
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;

  /// Clears to the sky colour and draws every item in the order plan_draws gives (opaque, nearest first;
  /// floors; translucent), one instanced call per batch.
  void draw(const Scene& scene, int width, int height);
  /// Triangles submitted by the last draw().
  [[nodiscard]] std::uint64_t last_triangles() const { return last_triangles_; }
  /// Draw calls made by the last draw(): one per batch of the draw plan.
  [[nodiscard]] std::size_t last_draw_calls() const { return last_draw_calls_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint64_t last_triangles_ = 0;
  std::size_t last_draw_calls_ = 0;
};

/// Column-major perspective projection (OpenGL clip space).
Eigen::Matrix4f perspective(float fov_y_degrees, float aspect, float near_plane, float far_plane);
/// Column-major view matrix looking from eye at target with +z up.
Eigen::Matrix4f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up);

}  // namespace rfbsim::sim
