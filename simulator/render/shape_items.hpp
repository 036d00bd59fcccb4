// SPDX-License-Identifier: GPL-2.0-or-later
// Small helpers the scene-builder parts share: colours and unit shapes placed in a local frame.
#pragma once

#include <cstdint>
#include <vector>

#include "render/draw_list.hpp"

namespace rfbsim::sim {

/// 0xRRGGBB -> RGB in 0..1.
Eigen::Vector3f rgb(std::uint32_t hex);

/// A unit `shape` scaled to `size` (m, full extents) with its centre at `centre` in `frame`.
DrawItem shape_item(Shape shape, const Eigen::Affine3f& frame, const Eigen::Vector3f& centre,
                    const Eigen::Vector3f& size, const Eigen::Vector3f& color);

/// A box in `frame`: the common case of shape_item.
inline DrawItem box_item(const Eigen::Affine3f& frame, const Eigen::Vector3f& centre, const Eigen::Vector3f& size,
                         const Eigen::Vector3f& color) {
  return shape_item(Shape::Box, frame, centre, size, color);
}

/// A soft round shadow on the floor at (x, y): a faint wide disc under a darker narrow one, radius m.
void append_soft_shadow(std::vector<DrawItem>& items, float x, float y, float radius);

/// A well-mixed 32-bit hash, so that nearby ids and positions give unrelated picks (deterministic).
std::uint32_t mix_hash(std::uint32_t value);

/// Hash of a position rounded to centimetres: the same prop always gets the same look.
std::uint32_t position_hash(double x, double y);

}  // namespace rfbsim::sim
