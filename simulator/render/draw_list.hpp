// SPDX-License-Identifier: GPL-2.0-or-later
// Scene: what to draw this frame, as plain data. The scene builder fills it from the world; the GL
// renderer draws it; a top-down replay view or a debug overlay could draw the same list.
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace rfbsim::sim {

/// Unit shapes the renderer knows; each item scales and places one.
enum class Shape {
  Box,       ///< cube from -0.5 to 0.5 on every axis
  Sphere,    ///< radius 0.5 at the origin
  Cylinder,  ///< radius 0.5, z from -0.5 to 0.5
  Disc,      ///< radius 0.5 in the z = 0 plane, facing +z
};

/// How a surface is shaded beyond its colour.
enum class Surface {
  Plain,
  Floor,  ///< a tiled floor pattern, so that motion over it reads clearly
  Wall,   ///< darkened toward the floor, so that wall bases read as contact
};

/// One shape placed in the world (z up, metres).
struct DrawItem {
  Shape shape = Shape::Box;
  Surface surface = Surface::Plain;
  Eigen::Affine3f model = Eigen::Affine3f::Identity();  ///< unit shape -> world
  Eigen::Vector3f color{0.8f, 0.8f, 0.8f};              ///< linear-ish RGB, 0..1
  float opacity = 1.0f;                                  ///< < 1 for shadows, drawn after opaque items
};

/// A perspective camera.
struct ViewCamera {
  Eigen::Vector3f eye{0.0f, -5.0f, 2.0f};
  Eigen::Vector3f target{0.0f, 0.0f, 1.0f};
  float fov_y_degrees = 60.0f;
};

/// Everything one frame shows.
struct Scene {
  ViewCamera camera;
  Eigen::Vector3f sky{0.62f, 0.72f, 0.82f};     ///< background and fog colour
  Eigen::Vector3f sun_direction{0.35f, 0.6f, -1.0f};   ///< direction the light travels
  float fog_start = 12.0f;                       ///< m from the eye
  float fog_end = 40.0f;
  std::vector<DrawItem> items;
};

/// Whether two scenes would draw the same picture (exact comparison). The app skips rendering a frame
/// whose scene equals the last one drawn: an idle view costs no GPU or CPU time.
inline bool same_scene(const Scene& a, const Scene& b) {
  const auto same_item = [](const DrawItem& x, const DrawItem& y) {
    return x.shape == y.shape && x.surface == y.surface && x.model.matrix() == y.model.matrix() &&
           x.color == y.color && x.opacity == y.opacity;
  };
  if (a.camera.eye != b.camera.eye || a.camera.target != b.camera.target ||
      a.camera.fov_y_degrees != b.camera.fov_y_degrees || a.sky != b.sky || a.sun_direction != b.sun_direction ||
      a.fog_start != b.fog_start || a.fog_end != b.fog_end || a.items.size() != b.items.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.items.size(); ++i) {
    if (!same_item(a.items[i], b.items[i])) return false;
  }
  return true;
}

}  // namespace rfbsim::sim
