// SPDX-License-Identifier: GPL-2.0-or-later
// The navigation debug overlay (sim_rfb --debug-overlay): what the robot's stack planned and what it
// believes, drawn on the floor as a few flat shapes. Plain data, no GL; build_scene appends it last.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/draw_list.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// How the overlay is drawn and how coarse it may get, so that its item count stays bounded.
struct NavOverlayStyle {
  float ribbon_width = 0.05f;          ///< m, across the path and trajectory ribbons
  float path_lift = 0.02f;             ///< m, the global path's ribbon centre above the floor
  float trajectory_lift = 0.03f;       ///< m, the local trajectory's, above the path where they overlap
  double path_tolerance = 0.02;        ///< m, a dropped path point lies at most this far from its ribbon
  std::size_t max_path_segments = 96;  ///< the global path's ribbon never has more boxes than this
  std::size_t max_trajectory_segments = 32;  ///< the same for the local trajectory
  double social_cell = 0.2;            ///< m, the social cost is drawn in squares at least this wide
  std::size_t max_social_patches = 256;  ///< squares grow beyond social_cell until their count fits this
  int social_levels = 6;               ///< cost steps (colour and opacity); neighbours on one step merge
  Eigen::Vector3f path_color{0.1f, 0.75f, 0.3f};        ///< green, as rviz shows a global plan
  Eigen::Vector3f trajectory_color{0.15f, 0.45f, 1.0f};  ///< blue
  Eigen::Vector3f goal_color{0.85f, 0.2f, 0.75f};       ///< magenta
  Eigen::Vector3f estimate_color{0.1f, 0.85f, 0.95f};   ///< cyan, where localization believes the robot is
};

/// Drops points of a polyline that lie within `tolerance` (m) of the segment kept around them, splitting
/// at the worst point first (Douglas-Peucker), and stops at `max_segments` segments (so the tolerance is
/// only met when that many suffice). Points that are not finite are skipped; the first and last finite
/// points are kept. Fewer than two finite points give them back as they are.
std::vector<Eigen::Vector2d> simplify_polyline(const std::vector<Eigen::Vector2d>& points, double tolerance,
                                               std::size_t max_segments);

/// An axis-aligned rectangle on the floor (m) and the highest social cost (1..252) inside it.
struct CostPatch {
  double min_x = 0.0;
  double min_y = 0.0;
  double max_x = 0.0;
  double max_y = 0.0;
  std::uint8_t cost = 0;
};

/// The cells of `grid` with cost > 0 as at most `style.max_social_patches` rectangles: cells are grouped
/// into square blocks of at least `style.social_cell` m (each takes its cells' highest cost, clamped to
/// 252), and neighbouring blocks in a row whose costs fall on the same of `style.social_levels` steps are
/// merged. Rows come bottom to top, each left to right. A grid whose size and cells disagree, or whose
/// resolution is not positive, gives none.
std::vector<CostPatch> social_cost_patches(const CostmapGrid& grid, const NavOverlayStyle& style = {});

/// Appends the overlay of `robot`: translucent social-cost squares (yellow to red, more opaque with cost),
/// the global path and the local trajectory as flat ribbons, the goal as a disc with an arrow along its
/// yaw, and a translucent disc of the footprint with a heading tick at localization's estimate. Parts the stack has not
/// filled (an empty path, no goal) and points that are not finite are left out.
void append_nav_overlay(std::vector<DrawItem>& items, const Robot& robot, const NavOverlayStyle& style = {});

}  // namespace rfbsim::sim
