// SPDX-License-Identifier: GPL-2.0-or-later
// The navigation debug overlay: paths simplified to few segments, social cost as merged squares at the
// right places, everything bounded, and nothing in the scene unless asked for and there is a robot.
#include "render/nav_overlay.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "render/draw_batches.hpp"
#include "render/scene_builder.hpp"

namespace {

using rfbsim::sim::CostPatch;
using rfbsim::sim::DrawItem;
using rfbsim::sim::NavOverlayStyle;
using Eigen::Vector2d;

// A robot at (2, 2) whose stack has filled every part of its view: an L-shaped plan, a short rollout,
// a goal and three social cells.
rfbsim::sim::Robot planned_robot() {
  rfbsim::sim::Robot robot;
  robot.pose = {2.0, 2.0, 0.0};
  robot.estimate = {2.1, 2.0, 0.1};
  for (int i = 0; i <= 40; ++i) robot.nav.global_path.push_back({2.0 + 0.05 * i, 2.0});  // to (4, 2)
  for (int i = 1; i <= 40; ++i) robot.nav.global_path.push_back({4.0, 2.0 + 0.05 * i});  // up to (4, 4)
  for (int i = 0; i <= 10; ++i) robot.nav.local_trajectory.push_back({2.0 + 0.03 * i, 2.0});
  robot.nav.goal = rfbsim::sim::Pose2{4.0, 4.0, 1.5707963};
  robot.nav.social = rfbsim::sim::CostmapGrid::sized(10, 10, 0.2, 1.0, 2.0);
  robot.nav.social.set({3, 4}, 100);
  robot.nav.social.set({4, 4}, 110);  // on 100's cost step: one patch with it
  robot.nav.social.set({5, 4}, 30);   // a lower step: a patch of its own
  robot.nav.social.set({7, 1}, 252);
  return robot;
}

rfbsim::sim::World world_with(const rfbsim::sim::Robot& robot) {
  rfbsim::sim::World world;
  world.map = rfbsim::sim::grid_from_text({"......", "......", "......", "......", "......", "......"}, 1.0);
  world.robot = robot;
  return world;
}

bool same_items(const std::vector<DrawItem>& a, const std::vector<DrawItem>& b) {
  rfbsim::sim::Scene x, y;
  x.items = a;
  y.items = b;
  return rfbsim::sim::same_scene(x, y);
}

}  // namespace

TEST_CASE("overlay: a polyline keeps its corners and drops points along straight runs", "[overlay]") {
  const auto robot = planned_robot();
  const auto simple = rfbsim::sim::simplify_polyline(robot.nav.global_path, 0.02, 96);
  REQUIRE(simple.size() == 3);
  CHECK(simple[0].isApprox(Vector2d(2.0, 2.0)));
  CHECK(simple[1].isApprox(Vector2d(4.0, 2.0)));
  CHECK(simple[2].isApprox(Vector2d(4.0, 4.0)));

  // Points off the line by less than the tolerance go, by more stay; points that are not finite are skipped.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Vector2d> bumpy{{0, 0}, {1, 0.01}, {nan, 1}, {2, 0}, {3, 0.5}, {4, 0}};
  const auto kept = rfbsim::sim::simplify_polyline(bumpy, 0.02, 96);
  REQUIRE(kept.size() == 4);
  CHECK(kept[1].isApprox(Vector2d(2, 0)));
  CHECK(kept[2].isApprox(Vector2d(3, 0.5)));
  // Too few points come back as they are.
  CHECK(rfbsim::sim::simplify_polyline({{1, 2}}, 0.02, 96).size() == 1);
  CHECK(rfbsim::sim::simplify_polyline({{1, 2}, {nan, 0}, {3, 4}}, 0.02, 96).size() == 2);
  CHECK(rfbsim::sim::simplify_polyline({}, 0.02, 96).empty());
}

TEST_CASE("overlay: a zig-zag path of 400 points is cut off at the segment budget", "[overlay]") {
  std::vector<Vector2d> zigzag;
  for (int i = 0; i < 400; ++i) zigzag.push_back({0.05 * i, (i % 2) * 0.1});
  const auto simple = rfbsim::sim::simplify_polyline(zigzag, 0.02, 96);
  CHECK(simple.size() == 97);
  CHECK(simple.front().isApprox(zigzag.front()));
  CHECK(simple.back().isApprox(zigzag.back()));
}

TEST_CASE("overlay: social cells become patches at their places with their highest cost", "[overlay]") {
  const auto patches = rfbsim::sim::social_cost_patches(planned_robot().nav.social);
  REQUIRE(patches.size() == 3);
  // Bottom row first: cell (7, 1) of the 0.2 m grid at (1, 2).
  CHECK(patches[0].min_x == Approx(2.4));
  CHECK(patches[0].max_x == Approx(2.6));
  CHECK(patches[0].min_y == Approx(2.2));
  CHECK(patches[0].max_y == Approx(2.4));
  CHECK(patches[0].cost == 252);
  // Row 4: cells 3 and 4 merged, then cell 5 on its own.
  CHECK(patches[1].min_x == Approx(1.6));
  CHECK(patches[1].max_x == Approx(2.0));
  CHECK(patches[1].min_y == Approx(2.8));
  CHECK(patches[1].max_y == Approx(3.0));
  CHECK(patches[1].cost == 110);
  CHECK(patches[2].min_x == Approx(2.0));
  CHECK(patches[2].max_x == Approx(2.2));
  CHECK(patches[2].cost == 30);

  // A fine grid is drawn in 0.2 m blocks: 4 x 4 cells of 0.05 m, each block its highest cell.
  auto fine = rfbsim::sim::CostmapGrid::sized(8, 8, 0.05, -1.0, 0.0);
  fine.set({1, 1}, 40);
  fine.set({2, 3}, 200);
  fine.set({6, 6}, 60);
  fine.set({7, 7}, 255);  // not a social cost: clamped to 252
  const auto blocks = rfbsim::sim::social_cost_patches(fine);
  REQUIRE(blocks.size() == 2);
  CHECK(blocks[0].min_x == Approx(-1.0));
  CHECK(blocks[0].max_x == Approx(-0.8));
  CHECK(blocks[0].min_y == Approx(0.0));
  CHECK(blocks[0].max_y == Approx(0.2));
  CHECK(blocks[0].cost == 200);
  CHECK(blocks[1].min_x == Approx(-0.8));
  CHECK(blocks[1].max_y == Approx(0.4));
  CHECK(blocks[1].cost == 252);

  // Grids that make no sense give nothing.
  auto broken = fine;
  broken.costs.pop_back();
  CHECK(rfbsim::sim::social_cost_patches(broken).empty());
  broken = fine;
  broken.resolution = 0.0;
  CHECK(rfbsim::sim::social_cost_patches(broken).empty());
  broken = fine;
  broken.origin_x = std::nan("");
  CHECK(rfbsim::sim::social_cost_patches(broken).empty());
  CHECK(rfbsim::sim::social_cost_patches(rfbsim::sim::CostmapGrid{}).empty());
}

TEST_CASE("overlay: ribbons, goal and estimate are drawn where the plan puts them", "[overlay]") {
  const auto robot = planned_robot();
  const NavOverlayStyle style;
  std::vector<DrawItem> items;
  rfbsim::sim::append_nav_overlay(items, robot, style);
  // 3 social squares, 2 path boxes, 1 trajectory box, 3 goal items, 2 estimate items.
  REQUIRE(items.size() == 11);
  for (std::size_t i = 0; i < 3; ++i) CHECK(items[i].opacity < 1.0f);
  CHECK(items[0].opacity > items[1].opacity);  // 252 is more opaque than 110
  // The plan's first leg: a box from (2, 2) to (4, 2), its ends overlapping by half the ribbon's width.
  const DrawItem& leg = items[3];
  CHECK(leg.color == style.path_color);
  CHECK(leg.model.translation().isApprox(Eigen::Vector3f(3.0f, 2.0f, 0.02f)));
  CHECK(leg.model.linear().col(0).norm() == Approx(2.05f));
  CHECK(leg.model.linear().col(1).norm() == Approx(0.05f));
  CHECK(items[4].model.translation().isApprox(Eigen::Vector3f(4.0f, 3.0f, 0.02f)));
  // The rollout above the plan.
  CHECK(items[5].color == style.trajectory_color);
  CHECK(items[5].model.translation().isApprox(Eigen::Vector3f(2.15f, 2.0f, 0.03f)));
  // The goal disc at (4, 4), its arrow pointing along +y (yaw pi/2).
  CHECK(items[6].model.translation().isApprox(Eigen::Vector3f(4.0f, 4.0f, 0.012f)));
  CHECK(items[7].model.translation().isApprox(Eigen::Vector3f(4.0f, 4.18f, 0.02f), 1e-5f));
  // The estimate: a translucent disc of the footprint at (2.1, 2).
  CHECK(items[9].opacity < 1.0f);
  CHECK(items[9].model.translation().isApprox(Eigen::Vector3f(2.1f, 2.0f, 0.014f)));
  CHECK(items[9].model.linear().col(0).norm() == Approx(0.32f));

  // Broken inputs leave their parts out.
  auto broken = robot;
  broken.nav.goal->yaw = std::nan("");
  broken.estimate.x = std::nan("");
  items.clear();
  rfbsim::sim::append_nav_overlay(items, broken, style);
  CHECK(items.size() == 6);
}

TEST_CASE("overlay: in the scene only when asked for and with a robot, as the last items", "[overlay]") {
  const auto world = world_with(planned_robot());
  rfbsim::sim::SceneStyle on;
  on.debug_overlay = true;
  const auto plain = rfbsim::sim::build_scene(world);
  const auto overlaid = rfbsim::sim::build_scene(world, on);
  std::vector<DrawItem> overlay;
  rfbsim::sim::append_nav_overlay(overlay, *world.robot);
  REQUIRE(overlaid.items.size() == plain.items.size() + overlay.size());
  CHECK(same_items({overlaid.items.begin(), overlaid.items.begin() + static_cast<std::ptrdiff_t>(plain.items.size())},
                   plain.items));
  CHECK(same_items({overlaid.items.end() - static_cast<std::ptrdiff_t>(overlay.size()), overlaid.items.end()},
                   overlay));

  // Off, the scene is the one the old signature builds; on without a robot, nothing is added.
  CHECK(rfbsim::sim::same_scene(plain, rfbsim::sim::build_scene(world, rfbsim::sim::SceneStyle{})));
  auto no_robot = world;
  no_robot.robot.reset();
  CHECK(rfbsim::sim::same_scene(rfbsim::sim::build_scene(no_robot), rfbsim::sim::build_scene(no_robot, on)));
}

TEST_CASE("overlay: a 400-point path and a full 80 x 80 social window stay within the item budget", "[overlay]") {
  rfbsim::sim::Robot robot;
  // A winding 20 m plan (a sine of 1 m amplitude) and a rollout of 68 points with noise-like wiggles.
  for (int i = 0; i < 400; ++i) {
    robot.nav.global_path.push_back({0.05 * i, std::sin(0.05 * i) + 0.03 * ((i * 7) % 3)});
  }
  for (int i = 0; i < 68; ++i) robot.nav.local_trajectory.push_back({0.02 * i, 0.04 * ((i * 5) % 3)});
  // Every cell set, in a checkerboard of 5 x 5 cells from the lowest to the highest cost: the worst case,
  // since 0.2 m blocks (4 cells) would be 400 and the 256 blocks of 5 cells that fit the budget never merge.
  robot.nav.social = rfbsim::sim::CostmapGrid::sized(80, 80, 0.05, -2.0, -2.0);
  for (int row = 0; row < 80; ++row) {
    for (int col = 0; col < 80; ++col) robot.nav.social.set({col, row}, (col / 5 + row / 5) % 2 != 0 ? 252 : 1);
  }
  robot.nav.goal = rfbsim::sim::Pose2{19.95, 0.0, 0.0};
  const NavOverlayStyle style;
  const auto patches = rfbsim::sim::social_cost_patches(robot.nav.social, style);
  CHECK(patches.size() == style.max_social_patches);
  // The patches cover the whole window exactly once.
  double area = 0.0;
  for (const CostPatch& p : patches) area += (p.max_x - p.min_x) * (p.max_y - p.min_y);
  CHECK(area == Approx(16.0));

  std::vector<DrawItem> items;
  rfbsim::sim::append_nav_overlay(items, robot, style);
  std::size_t path_items = 0, trajectory_items = 0;
  for (const DrawItem& item : items) {
    path_items += item.color == style.path_color ? 1u : 0u;
    trajectory_items += item.color == style.trajectory_color ? 1u : 0u;
  }
  INFO("path " << path_items << ", trajectory " << trajectory_items << ", all " << items.size());
  CHECK(path_items <= 96);
  CHECK(path_items >= 10);  // the sine's bends are kept
  CHECK(trajectory_items <= 32);
  CHECK(items.size() <= 256 + 96 + 32 + 5);
}

TEST_CASE("overlay: its translucent squares are drawn after every opaque item, in one batch", "[overlay]") {
  rfbsim::sim::SceneStyle on;
  on.debug_overlay = true;
  const auto scene = rfbsim::sim::build_scene(world_with(planned_robot()), on);
  const auto plan = rfbsim::sim::plan_draws(scene);
  // Opaque batches first (the ribbons and the goal among them), then the blended ones.
  bool blending = false;
  std::size_t square_batches = 0;
  for (const auto& batch : plan.batches) {
    CHECK((batch.blended || !blending));
    blending = blending || batch.blended;
    if (batch.blended && batch.shape == rfbsim::sim::Shape::Box) {
      ++square_batches;
      CHECK(batch.count == 3);  // the three social patches
    }
    for (std::size_t i = batch.first; i < batch.first + batch.count; ++i) {
      CHECK((scene.items[plan.order[i]].opacity < 1.0f) == batch.blended);
    }
  }
  CHECK(square_batches == 1);
}
