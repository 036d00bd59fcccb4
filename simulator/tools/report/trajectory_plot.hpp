// SPDX-License-Identifier: GPL-2.0-or-later
// Trajectory plots for report.html: a session's paths from above as inline SVG, over its scenario's walls
// and props, which are drawn once per map and referenced by every plot that uses them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "session_samples.hpp"
#include "world/world.hpp"

namespace rfbsim::report {

/// An axis-aligned box in map metres; empty until a point is added.
struct Bounds {
  double min_x = 1e300, min_y = 1e300, max_x = -1e300, max_y = -1e300;
  [[nodiscard]] bool empty() const { return min_x > max_x; }
  void add(double x, double y);
  void add(const Bounds& other);
};

/// A scenario's walls and props in map metres, as an SVG group (`<g id="ID">...</g>`) to be placed once
/// in the page's definitions and drawn with `<use href="#ID"/>`.
struct MapDrawing {
  std::string id;          ///< the group's id: letters, digits and '-' only
  std::string definition;  ///< the <g> element
  Bounds bounds;           ///< the whole grid's extent
};

/// Draws `walls` as merged wall rectangles and `props` as their turned boxes. `id` must be a plain
/// identifier (the caller makes it; it is not data).
MapDrawing draw_map(const sim::GridMap& walls, const std::vector<sim::Prop>& props, const std::string& id);

/// The session's paths: people faint grey, the robot red, the avatar blue, each start a dot and each end a
/// square, over `map` when given (nullptr: no walls). At most about 480 px on its longer side.
std::string trajectory_svg(const SampledSession& session, const MapDrawing* map);

/// `points` with every point dropped that lies within `tolerance` of the line its kept neighbours span
/// (Ramer-Douglas-Peucker); the first and last points are always kept. Plots stay small without a visible
/// change when the tolerance is below a pixel.
std::vector<Eigen::Vector2d> simplify_path(const std::vector<Eigen::Vector2d>& points, double tolerance);

}  // namespace rfbsim::report
