// SPDX-License-Identifier: GPL-2.0-or-later
// The navigation debug overlay: polyline simplification, social-cost patches, and their flat shapes.
#include "render/nav_overlay.hpp"

#include <algorithm>
#include <cmath>

#include "render/shape_items.hpp"

namespace rfbsim::sim {

namespace {

bool finite(const Eigen::Vector2d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// A run of points[first..last] drawn as one segment, and its point farthest from that segment.
struct Span {
  std::size_t first = 0;
  std::size_t last = 0;
  std::size_t worst = 0;
  double worst_distance = 0.0;
};

Span make_span(const std::vector<Eigen::Vector2d>& points, std::size_t first, std::size_t last) {
  Span span{first, last, first, 0.0};
  for (std::size_t i = first + 1; i < last; ++i) {
    const double d = distance_to_segment(points[i], points[first], points[last]);
    if (d > span.worst_distance) {
      span.worst = i;
      span.worst_distance = d;
    }
  }
  return span;
}

// A flat box on the floor from a to b, `width` across, its ends overlapping the next box's at joints.
void append_ribbon(std::vector<DrawItem>& items, const std::vector<Eigen::Vector2d>& points, float width, float lift,
                   const Eigen::Vector3f& color) {
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector2d d = points[i] - points[i - 1];
    const double length = d.norm();
    if (length < 1e-6) continue;
    const Eigen::Vector2d mid = 0.5 * (points[i] + points[i - 1]);
    const Eigen::Affine3f frame =
        Eigen::Translation3f(static_cast<float>(mid.x()), static_cast<float>(mid.y()), lift) *
        Eigen::AngleAxisf(static_cast<float>(std::atan2(d.y(), d.x())), Eigen::Vector3f::UnitZ());
    const Eigen::Vector3f size{static_cast<float>(length) + width, width, 0.006f};
    items.push_back(box_item(frame, Eigen::Vector3f::Zero(), size, color));
  }
}

}  // namespace

std::vector<Eigen::Vector2d> simplify_polyline(const std::vector<Eigen::Vector2d>& points, double tolerance,
                                               std::size_t max_segments) {
  std::vector<Eigen::Vector2d> kept;
  kept.reserve(points.size());
  std::copy_if(points.begin(), points.end(), std::back_inserter(kept), finite);
  if (kept.size() < 3) return kept;

  // Split the span with the farthest point until every point is close enough or the budget is spent.
  std::vector<Span> spans{make_span(kept, 0, kept.size() - 1)};
  while (spans.size() < std::max<std::size_t>(max_segments, 1)) {
    std::size_t worst = 0;
    for (std::size_t i = 1; i < spans.size(); ++i) {
      if (spans[i].worst_distance > spans[worst].worst_distance) worst = i;  // ties: the earliest
    }
    const Span split = spans[worst];
    if (!(split.worst_distance > tolerance)) break;
    spans[worst] = make_span(kept, split.first, split.worst);
    spans.insert(spans.begin() + static_cast<std::ptrdiff_t>(worst) + 1, make_span(kept, split.worst, split.last));
  }

  std::vector<Eigen::Vector2d> out;
  out.reserve(spans.size() + 1);
  out.push_back(kept.front());
  for (const Span& span : spans) out.push_back(kept[span.last]);
  return out;
}

std::vector<CostPatch> social_cost_patches(const CostmapGrid& grid, const NavOverlayStyle& style) {
  std::vector<CostPatch> patches;
  if (grid.width <= 0 || grid.height <= 0 || !(grid.resolution > 0.0) || !std::isfinite(grid.origin_x) ||
      !std::isfinite(grid.origin_y) ||
      grid.costs.size() != static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height)) {
    return patches;
  }
  // Block side in cells: social_cell, or larger until the blocks fit the budget even when all are set.
  const auto blocks = [&](int side) {
    return static_cast<std::size_t>((grid.width + side - 1) / side) *
           static_cast<std::size_t>((grid.height + side - 1) / side);
  };
  int side = std::max(1, static_cast<int>(std::lround(style.social_cell / grid.resolution)));
  while (blocks(side) > std::max<std::size_t>(style.max_social_patches, 1)) ++side;
  const int levels = std::max(1, style.social_levels);
  const auto level_of = [levels](int cost) { return cost == 0 ? 0 : 1 + (cost - 1) * levels / 252; };

  const int block_cols = (grid.width + side - 1) / side;
  const int block_rows = (grid.height + side - 1) / side;
  std::vector<int> row_costs(static_cast<std::size_t>(block_cols));
  for (int br = 0; br < block_rows; ++br) {
    // Each block's highest cost in this row of blocks.
    std::fill(row_costs.begin(), row_costs.end(), 0);
    const int row_end = std::min(grid.height, (br + 1) * side);
    for (int row = br * side; row < row_end; ++row) {
      const std::uint8_t* cells = &grid.costs[grid.index({0, row})];
      for (int col = 0; col < grid.width; ++col) {
        int& block = row_costs[static_cast<std::size_t>(col / side)];
        block = std::max(block, std::min<int>(cells[col], 252));
      }
    }
    // Runs of blocks on one cost step become one patch.
    const double min_y = grid.origin_y + br * side * grid.resolution;
    const double max_y = grid.origin_y + row_end * grid.resolution;
    for (int bc = 0; bc < block_cols;) {
      const int cost = row_costs[static_cast<std::size_t>(bc)];
      int end = bc + 1;
      int highest = cost;
      while (end < block_cols && level_of(row_costs[static_cast<std::size_t>(end)]) == level_of(cost)) {
        highest = std::max(highest, row_costs[static_cast<std::size_t>(end)]);
        ++end;
      }
      if (cost > 0) {
        patches.push_back({grid.origin_x + bc * side * grid.resolution, min_y,
                           grid.origin_x + std::min(grid.width, end * side) * grid.resolution, max_y,
                           static_cast<std::uint8_t>(highest)});
      }
      bc = end;
    }
  }
  return patches;
}

void append_nav_overlay(std::vector<DrawItem>& items, const Robot& robot, const NavOverlayStyle& style) {
  const RobotNavView& nav = robot.nav;

  // Social cost: translucent squares just above the floor, under everything else; yellow to red with cost.
  for (const CostPatch& patch : social_cost_patches(nav.social, style)) {
    const float t = static_cast<float>(patch.cost) / 252.0f;
    const Eigen::Vector3f low{1.0f, 0.85f, 0.2f};
    const Eigen::Vector3f high{0.9f, 0.1f, 0.1f};
    DrawItem square = box_item(Eigen::Affine3f::Identity(),
                               {static_cast<float>((patch.min_x + patch.max_x) / 2.0),
                                static_cast<float>((patch.min_y + patch.max_y) / 2.0), 0.006f},
                               {static_cast<float>(patch.max_x - patch.min_x),
                                static_cast<float>(patch.max_y - patch.min_y), 0.002f},
                               low + t * (high - low));
    square.opacity = 0.25f + 0.45f * t;
    items.push_back(square);
  }

  // The plan and the chosen rollout as ribbons, the rollout on top where they overlap.
  append_ribbon(items, simplify_polyline(nav.global_path, style.path_tolerance, style.max_path_segments),
                style.ribbon_width, style.path_lift, style.path_color);
  append_ribbon(items,
                simplify_polyline(nav.local_trajectory, style.path_tolerance, style.max_trajectory_segments),
                0.8f * style.ribbon_width, style.trajectory_lift, style.trajectory_color);

  // The goal: a disc with an arrow along its yaw, the way the robot should face on arrival.
  if (nav.goal && std::isfinite(nav.goal->x) && std::isfinite(nav.goal->y) && std::isfinite(nav.goal->yaw)) {
    const Eigen::Affine3f goal =
        Eigen::Translation3f(static_cast<float>(nav.goal->x), static_cast<float>(nav.goal->y), 0.0f) *
        Eigen::AngleAxisf(static_cast<float>(nav.goal->yaw), Eigen::Vector3f::UnitZ());
    items.push_back(shape_item(Shape::Disc, goal, {0.0f, 0.0f, 0.012f}, {0.3f, 0.3f, 1.0f}, style.goal_color));
    items.push_back(box_item(goal, {0.18f, 0.0f, 0.02f}, {0.36f, 0.06f, 0.01f}, style.goal_color));
    // The arrowhead: a square turned 45 degrees, half of it past the shaft's end.
    const Eigen::Affine3f tip = goal * Eigen::Translation3f(0.36f, 0.0f, 0.02f) *
                                Eigen::AngleAxisf(0.785398f, Eigen::Vector3f::UnitZ());
    items.push_back(box_item(tip, Eigen::Vector3f::Zero(), {0.12f, 0.12f, 0.01f}, style.goal_color));
  }

  // Localization's belief: a translucent footprint with a heading tick, apart from the drawn robot when it drifts.
  const Pose2& e = robot.estimate;
  if (std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.yaw)) {
    const Eigen::Affine3f at = Eigen::Translation3f(static_cast<float>(e.x), static_cast<float>(e.y), 0.0f) *
                               Eigen::AngleAxisf(static_cast<float>(e.yaw), Eigen::Vector3f::UnitZ());
    const auto d = 2.0f * static_cast<float>(robot.radius);
    DrawItem footprint = shape_item(Shape::Disc, at, {0.0f, 0.0f, 0.014f}, {d, d, 1.0f}, style.estimate_color);
    footprint.opacity = 0.35f;
    items.push_back(footprint);
    items.push_back(box_item(at, {0.75f * d, 0.0f, 0.016f}, {0.5f * d, 0.04f, 0.006f}, style.estimate_color));
  }
}

}  // namespace rfbsim::sim
