// SPDX-License-Identifier: GPL-2.0-or-later
// DistanceField: the exact squared Euclidean distance transform, one dimension at a time.
#include "map/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rfbsim::sim {

namespace {

constexpr double kFar = 1e20;

// One-dimensional squared distance transform of a sampled function f (Felzenszwalb & Huttenlocher 2012):
// d[q] = min_p ((q - p)^2 + f[p]), by the lower envelope of the parabolas rooted at each p.
void transform_1d(const std::vector<double>& f, std::vector<double>& d, std::vector<int>& roots,
                  std::vector<double>& bounds) {
  const int n = static_cast<int>(f.size());
  roots.assign(static_cast<std::size_t>(n), 0);
  bounds.assign(static_cast<std::size_t>(n) + 1, 0.0);
  d.assign(static_cast<std::size_t>(n), kFar);
  int k = 0;
  roots[0] = 0;
  bounds[0] = -2.0 * kFar;
  bounds[1] = kFar;
  const auto at = [&f](int i) { return f[static_cast<std::size_t>(i)]; };
  const auto intersection = [&at](int q, int p) {
    return ((at(q) + q * q) - (at(p) + p * p)) / (2.0 * q - 2.0 * p);
  };
  for (int q = 1; q < n; ++q) {
    // bounds[0] is far below any intersection (values are at most kFar), so this stops at k = 0.
    double s = intersection(q, roots[static_cast<std::size_t>(k)]);
    while (s <= bounds[static_cast<std::size_t>(k)]) {
      --k;
      s = intersection(q, roots[static_cast<std::size_t>(k)]);
    }
    ++k;
    roots[static_cast<std::size_t>(k)] = q;
    bounds[static_cast<std::size_t>(k)] = s;
    bounds[static_cast<std::size_t>(k) + 1] = kFar;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (bounds[static_cast<std::size_t>(k) + 1] < q) ++k;
    const int p = roots[static_cast<std::size_t>(k)];
    d[static_cast<std::size_t>(q)] = (q - p) * (q - p) + at(p);
  }
}

}  // namespace

DistanceField::DistanceField(const GridMap& map) : map_(map) {
  // A one-cell border of wall around the grid, so that the map's edge counts as wall.
  const int w = map.width + 2;
  const int h = map.height + 2;
  std::vector<double> grid(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      grid[static_cast<std::size_t>(row * w + col)] = map.is_occupied(col - 1, row - 1) ? 0.0 : kFar;
    }
  }
  std::vector<double> f;
  std::vector<double> d;
  std::vector<int> roots;
  std::vector<double> bounds;
  for (int col = 0; col < w; ++col) {
    f.resize(static_cast<std::size_t>(h));
    for (int row = 0; row < h; ++row) f[static_cast<std::size_t>(row)] = grid[static_cast<std::size_t>(row * w + col)];
    transform_1d(f, d, roots, bounds);
    for (int row = 0; row < h; ++row) grid[static_cast<std::size_t>(row * w + col)] = d[static_cast<std::size_t>(row)];
  }
  for (int row = 0; row < h; ++row) {
    f.assign(grid.begin() + row * w, grid.begin() + (row + 1) * w);
    transform_1d(f, d, roots, bounds);
    std::copy(d.begin(), d.end(), grid.begin() + row * w);
  }
  metres_.resize(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height));
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      metres_[static_cast<std::size_t>(row * map.width + col)] = static_cast<float>(
          std::sqrt(grid[static_cast<std::size_t>((row + 1) * w + col + 1)]) * map.resolution);
    }
  }
}

double DistanceField::at_cell(Cell c) const {
  if (c.col < 0 || c.row < 0 || c.col >= map_.width || c.row >= map_.height) return 0.0;
  return metres_[static_cast<std::size_t>(c.row * map_.width + c.col)];
}

double DistanceField::interpolated(Eigen::Vector2d p) const {
  // Bilinear between the four nearest cell centres.
  const double u = p.x() / map_.resolution - 0.5;
  const double v = p.y() / map_.resolution - 0.5;
  const int c0 = static_cast<int>(std::floor(u));
  const int r0 = static_cast<int>(std::floor(v));
  const double fu = u - c0;
  const double fv = v - r0;
  const double a = at_cell({c0, r0});
  const double b = at_cell({c0 + 1, r0});
  const double c = at_cell({c0, r0 + 1});
  const double d = at_cell({c0 + 1, r0 + 1});
  return (a * (1 - fu) + b * fu) * (1 - fv) + (c * (1 - fu) + d * fu) * fv;
}

double DistanceField::at(double x, double y) const {
  if (metres_.empty()) return 0.0;
  return std::max(0.0, interpolated(map_.to_map_frame(x, y)) - 0.5 * map_.resolution);
}

Eigen::Vector2d DistanceField::gradient(double x, double y) const {
  if (metres_.empty()) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d p = map_.to_map_frame(x, y);
  const double h = 0.5 * map_.resolution;
  const double gx = interpolated(p + Eigen::Vector2d(h, 0)) - interpolated(p - Eigen::Vector2d(h, 0));
  const double gy = interpolated(p + Eigen::Vector2d(0, h)) - interpolated(p - Eigen::Vector2d(0, h));
  const Eigen::Vector2d g_map(gx, gy);
  const double norm = g_map.norm();
  if (norm < 1e-12) return Eigen::Vector2d::Zero();
  // Back to the world frame: rotate by the map's yaw.
  const double c = std::cos(map_.origin_yaw);
  const double s = std::sin(map_.origin_yaw);
  return Eigen::Vector2d(c * g_map.x() - s * g_map.y(), s * g_map.x() + c * g_map.y()) / norm;
}

}  // namespace rfbsim::sim
