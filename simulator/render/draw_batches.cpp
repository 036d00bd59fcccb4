// SPDX-License-Identifier: GPL-2.0-or-later
// plan_draws: sort opaque items front to back per shape, floors last, translucent ones as they come.
#include "render/draw_batches.hpp"

#include <algorithm>

namespace rfbsim::sim {

namespace {

// Appends the batches of `indices` (already in drawing order), one per run of equal shapes.
void append_runs(DrawPlan& plan, const Scene& scene, const std::vector<std::uint32_t>& indices, bool blended) {
  for (const std::uint32_t index : indices) {
    const Shape shape = scene.items[index].shape;
    if (plan.batches.empty() || plan.batches.back().shape != shape || plan.batches.back().blended != blended) {
      plan.batches.push_back({shape, plan.order.size(), 0, blended});
    }
    plan.order.push_back(index);
    ++plan.batches.back().count;
  }
}

}  // namespace

DrawPlan plan_draws(const Scene& scene) {
  const auto& items = scene.items;
  std::vector<std::uint32_t> standing;
  std::vector<std::uint32_t> floors;
  std::vector<std::uint32_t> translucent;
  for (std::uint32_t i = 0; i < items.size(); ++i) {
    if (items[i].opacity < 1.0f) {
      translucent.push_back(i);
    } else if (items[i].surface == Surface::Floor) {
      floors.push_back(i);
    } else {
      standing.push_back(i);
    }
  }

  // Standing items: by shape, then by the squared distance of their centre from the eye.
  std::vector<float> distance(items.size(), 0.0f);
  for (const std::uint32_t i : standing) {
    distance[i] = (items[i].model.translation() - scene.camera.eye).squaredNorm();
  }
  // Shapes in their enum's order: Box, Sphere, Cylinder, Disc.
  std::stable_sort(standing.begin(), standing.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Shape sa = items[a].shape;
    const Shape sb = items[b].shape;
    return sa != sb ? sa < sb : distance[a] < distance[b];
  });
  std::stable_sort(floors.begin(), floors.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return items[a].shape < items[b].shape; });

  DrawPlan plan;
  plan.order.reserve(items.size());
  append_runs(plan, scene, standing, false);
  append_runs(plan, scene, floors, false);
  append_runs(plan, scene, translucent, true);
  return plan;
}

}  // namespace rfbsim::sim
