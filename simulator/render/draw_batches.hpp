// SPDX-License-Identifier: GPL-2.0-or-later
// The order a scene's items are drawn in, cut into batches that one instanced draw call each can draw.
// Plain data, no GL: the renderer follows the plan; tests check the order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/draw_list.hpp"

namespace rfbsim::sim {

/// Items order[first .. first + count) all have `shape` and are drawn by one call.
struct DrawBatch {
  Shape shape = Shape::Box;
  std::size_t first = 0;
  std::size_t count = 0;
  bool blended = false;  ///< translucent: blended over what is drawn, without writing depth
};

/// How to draw a scene: its items' order and the batches that order is cut into.
struct DrawPlan {
  std::vector<std::uint32_t> order;  ///< indices into Scene::items, in drawing order
  std::vector<DrawBatch> batches;    ///< cover `order` exactly, in drawing order
};

/// Plans the draws of `scene`:
/// 1. opaque items that stand in the scene, one batch per shape, each batch nearest to the camera first,
///    so that the depth test rejects hidden pixels before they are shaded (what llvmpipe spends most on);
/// 2. opaque floor surfaces: everything else stands on them, so they come last and are shaded only where
///    they show;
/// 3. translucent items (shadows) in scene order, a batch per run of one shape, since blending depends on
///    order.
/// Items at the same distance keep their scene order, so the plan (and the picture) is deterministic.
DrawPlan plan_draws(const Scene& scene);

}  // namespace rfbsim::sim
