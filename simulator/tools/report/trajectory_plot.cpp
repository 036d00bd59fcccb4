// SPDX-License-Identifier: GPL-2.0-or-later
// Trajectory plots: map drawings, path simplification and the per-session SVG.
#include "trajectory_plot.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "text_format.hpp"

namespace rfbsim::report {

namespace {

constexpr double kPlotPixels = 480.0;  // px, the longer side of the drawing area
constexpr double kPadPixels = 10.0;    // px around it
constexpr double kMinExtent = 1.0;     // m: a session that never moved still gets a readable plot
constexpr const char* kAvatarColour = "#1f6fd1";
constexpr const char* kRobotColour = "#d1421f";
constexpr const char* kPersonColour = "#777777";

std::string metres(double v) { return format_fixed(v, 2); }

std::string polygon(const std::vector<Eigen::Vector2d>& corners, const char* fill) {
  std::string out = "<polygon fill=\"";
  out += fill;
  out += "\" points=\"";
  for (const Eigen::Vector2d& p : corners) out += metres(p.x()) + "," + metres(p.y()) + " ";
  out.back() = '"';
  return out + "/>";
}

// Distance from p to the segment a-b.
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

std::string polyline(const std::vector<Eigen::Vector2d>& points, const char* colour, const char* extra) {
  std::string out = "<polyline fill=\"none\" stroke=\"";
  out += colour;
  out += "\" stroke-width=\"1.5\" vector-effect=\"non-scaling-stroke\" stroke-linejoin=\"round\"";
  out += extra;
  out += " points=\"";
  for (const Eigen::Vector2d& p : points) out += metres(p.x()) + "," + metres(p.y()) + " ";
  out.back() = '"';
  return out + "/>";
}

// A dot at the start and a square at the end, `size` m across.
std::string end_markers(const std::vector<Eigen::Vector2d>& points, const char* colour, double size) {
  if (points.empty()) return "";
  const Eigen::Vector2d& a = points.front();
  const Eigen::Vector2d& b = points.back();
  return "<circle fill=\"" + std::string(colour) + "\" cx=\"" + metres(a.x()) + "\" cy=\"" + metres(a.y()) +
         "\" r=\"" + format_fixed(size / 2, 3) + "\"/><rect fill=\"none\" stroke=\"" + colour +
         "\" stroke-width=\"1.5\" vector-effect=\"non-scaling-stroke\" x=\"" + format_fixed(b.x() - size / 2, 3) +
         "\" y=\"" + format_fixed(b.y() - size / 2, 3) + "\" width=\"" + format_fixed(size, 3) + "\" height=\"" +
         format_fixed(size, 3) + "\"/>";
}

}  // namespace

void Bounds::add(double x, double y) {
  min_x = std::min(min_x, x);
  min_y = std::min(min_y, y);
  max_x = std::max(max_x, x);
  max_y = std::max(max_y, y);
}

void Bounds::add(const Bounds& other) {
  if (other.empty()) return;
  add(other.min_x, other.min_y);
  add(other.max_x, other.max_y);
}

MapDrawing draw_map(const sim::GridMap& walls, const std::vector<sim::Prop>& props, const std::string& id) {
  MapDrawing out;
  out.id = id;
  const double res = walls.resolution;
  const auto corner = [&](double col, double row) { return walls.to_world(Eigen::Vector2d(col * res, row * res)); };
  const double cols = walls.width, rows = walls.height;
  for (const auto& c : {corner(0, 0), corner(cols, 0), corner(0, rows), corner(cols, rows)}) {
    out.bounds.add(c.x(), c.y());
  }
  out.definition = "<g id=\"" + id + "\">";
  for (const sim::Prop& prop : props) {
    const Eigen::Vector2d u(std::cos(prop.yaw) * prop.size_x / 2, std::sin(prop.yaw) * prop.size_x / 2);
    const Eigen::Vector2d v(-std::sin(prop.yaw) * prop.size_y / 2, std::cos(prop.yaw) * prop.size_y / 2);
    const Eigen::Vector2d c(prop.x, prop.y);
    out.definition += polygon({c - u - v, c + u - v, c + u + v, c - u + v}, "#c8c8c8");
  }
  for (const sim::WallRect& r : sim::merge_wall_rectangles(walls)) {
    const double c0 = r.first_column, r0 = r.first_row, c1 = c0 + r.columns, r1 = r0 + r.rows;
    out.definition += polygon({corner(c0, r0), corner(c1, r0), corner(c1, r1), corner(c0, r1)}, "#404040");
  }
  out.definition += "</g>";
  return out;
}

std::vector<Eigen::Vector2d> simplify_path(const std::vector<Eigen::Vector2d>& points, double tolerance) {
  if (points.size() <= 2) return points;
  std::vector<bool> keep(points.size(), false);
  keep.front() = keep.back() = true;
  // An explicit stack of spans rather than recursion: a long wandering path must not run out of stack.
  std::vector<std::pair<std::size_t, std::size_t>> spans = {{0, points.size() - 1}};
  while (!spans.empty()) {
    const auto [first, last] = spans.back();
    spans.pop_back();
    double farthest = -1.0;
    std::size_t at = first;
    for (std::size_t i = first + 1; i < last; ++i) {
      const double d = segment_distance(points[i], points[first], points[last]);
      if (d > farthest) {
        farthest = d;
        at = i;
      }
    }
    if (farthest > tolerance) {
      keep[at] = true;
      spans.push_back({first, at});
      spans.push_back({at, last});
    }
  }
  std::vector<Eigen::Vector2d> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (keep[i]) out.push_back(points[i]);
  }
  return out;
}

std::string trajectory_svg(const SampledSession& session, const MapDrawing* map) {
  // Every agent's path, and the box that holds them and the map.
  std::vector<Eigen::Vector2d> avatar, robot;
  std::vector<std::vector<Eigen::Vector2d>> people(session.person_ids.size());
  Bounds bounds;
  if (map != nullptr) bounds.add(map->bounds);
  for (const Sample& s : session.samples) {
    avatar.emplace_back(s.avatar.x, s.avatar.y);
    bounds.add(s.avatar.x, s.avatar.y);
    if (s.robot) {
      robot.emplace_back(s.robot->x, s.robot->y);
      bounds.add(s.robot->x, s.robot->y);
    }
    for (std::size_t i = 0; i < s.people.size(); ++i) {
      people[i].emplace_back(s.people[i].x, s.people[i].y);
      bounds.add(s.people[i].x, s.people[i].y);
    }
  }
  if (bounds.empty()) bounds.add(0.0, 0.0);
  const double cx = (bounds.min_x + bounds.max_x) / 2, cy = (bounds.min_y + bounds.max_y) / 2;
  bounds.add(cx - kMinExtent / 2, cy - kMinExtent / 2);
  bounds.add(cx + kMinExtent / 2, cy + kMinExtent / 2);

  // Metres to pixels: y up in the map, down in SVG.
  const double w = bounds.max_x - bounds.min_x, h = bounds.max_y - bounds.min_y;
  const double scale = kPlotPixels / std::max(w, h);
  const std::string width = format_fixed(w * scale + 2 * kPadPixels, 0);
  const std::string height = format_fixed(h * scale + 2 * kPadPixels, 0);
  std::string out = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + width + "\" height=\"" + height +
                    "\" viewBox=\"0 0 " + width + " " + height + "\" role=\"img\">";
  out += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>";
  out += "<g transform=\"matrix(" + format_fixed(scale, 4) + " 0 0 " + format_fixed(-scale, 4) + " " +
         format_fixed(kPadPixels - bounds.min_x * scale, 2) + " " + format_fixed(kPadPixels + bounds.max_y * scale, 2) +
         ")\">";
  if (map != nullptr) out += "<use href=\"#" + map->id + "\"/>";

  // Half a pixel of simplification is invisible and shrinks a five-minute session's paths many times over.
  const double tolerance = 0.5 / scale;
  const double marker = 8.0 / scale;
  for (const auto& path : people) {
    if (path.empty()) continue;
    const auto simple = simplify_path(path, tolerance);
    out += polyline(simple, kPersonColour, " stroke-opacity=\"0.35\"");
    out += end_markers(simple, kPersonColour, marker * 0.6);
  }
  for (const auto& [path, colour] : {std::pair{&robot, kRobotColour}, std::pair{&avatar, kAvatarColour}}) {
    if (path->empty()) continue;
    const auto simple = simplify_path(*path, tolerance);
    out += polyline(simple, colour, "");
    out += end_markers(simple, colour, marker);
  }
  out += "</g></svg>";
  return out;
}

}  // namespace rfbsim::report
