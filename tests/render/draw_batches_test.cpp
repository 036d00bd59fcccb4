// SPDX-License-Identifier: GPL-2.0-or-later
// Draw plans: opaque items by shape and nearest first, floors after them, translucent ones in scene order,
// and batches that cover the order exactly.
#include "render/draw_batches.hpp"

#include <catch2/catch.hpp>

namespace {

using rfbsim::sim::DrawItem;
using rfbsim::sim::Shape;
using rfbsim::sim::Surface;

DrawItem item(Shape shape, float x, float opacity = 1.0f, Surface surface = Surface::Plain) {
  DrawItem d;
  d.shape = shape;
  d.surface = surface;
  d.opacity = opacity;
  d.model = Eigen::Translation3f(x, 0.0f, 0.0f) * Eigen::Scaling(0.5f);
  return d;
}

}  // namespace

TEST_CASE("opaque items go by shape and nearest first, the floor after them, shadows last in scene order") {
  rfbsim::sim::Scene scene;
  scene.camera.eye = {0.0f, 0.0f, 0.0f};
  scene.items = {
      item(Shape::Box, 0.0f, 1.0f, Surface::Floor),  // 0: the floor
      item(Shape::Disc, 1.0f, 0.2f),                 // 1: a shadow
      item(Shape::Box, 9.0f),                        // 2: far box
      item(Shape::Sphere, 5.0f),                     // 3
      item(Shape::Box, 2.0f),                        // 4: near box
      item(Shape::Disc, 7.0f, 0.3f),                 // 5: another shadow
      item(Shape::Box, -2.0f),                       // 6: as near as 4, behind the eye, later in the scene
      item(Shape::Sphere, 3.0f),                     // 7
      item(Shape::Box, 4.0f, 0.5f),                  // 8: a translucent box between the shadows
      item(Shape::Disc, 8.0f, 0.3f),                 // 9
  };
  const rfbsim::sim::DrawPlan plan = rfbsim::sim::plan_draws(scene);
  CHECK(plan.order == std::vector<std::uint32_t>{4, 6, 2, 7, 3, 0, 1, 5, 8, 9});

  REQUIRE(plan.batches.size() == 6);
  const auto check_batch = [&](std::size_t i, Shape shape, std::size_t first, std::size_t count, bool blended) {
    INFO("batch " << i);
    CHECK(plan.batches[i].shape == shape);
    CHECK(plan.batches[i].first == first);
    CHECK(plan.batches[i].count == count);
    CHECK(plan.batches[i].blended == blended);
  };
  check_batch(0, Shape::Box, 0, 3, false);
  check_batch(1, Shape::Sphere, 3, 2, false);
  check_batch(2, Shape::Box, 5, 1, false);  // the floor
  check_batch(3, Shape::Disc, 6, 2, true);  // two shadows in a row
  check_batch(4, Shape::Box, 8, 1, true);
  check_batch(5, Shape::Disc, 9, 1, true);
}

TEST_CASE("an empty scene plans nothing") {
  const rfbsim::sim::DrawPlan plan = rfbsim::sim::plan_draws(rfbsim::sim::Scene{});
  CHECK(plan.order.empty());
  CHECK(plan.batches.empty());
}
