// SPDX-License-Identifier: GPL-2.0-or-later
// ProxemicLayer: the asymmetric Gaussian, its cutoff box, and stamping it into the dirty window.
#include "robot/costmap/proxemic_layer.hpp"

#include <algorithm>
#include <cmath>

namespace rfbsim::sim {

namespace {

// One person's Gaussian, set up once per person: the heading and the 1 / (2 variance) factors.
struct Gaussian {
  Eigen::Vector2d centre;
  double c = 1.0;  // cos and sin of the walking direction (any for a standing person)
  double s = 0.0;
  double front_variance = 0.0;  // m^2, along the heading where x > 0
  double variance = 0.0;        // m^2, behind and sideways
  double front_scale = 0.0;     // 1 / (2 front_variance)
  double scale = 0.0;           // 1 / (2 variance)

  Gaussian(const SeenPerson& person, const ProxemicLayerParams& params)
      : centre(person.position), front_variance(params.covariance), variance(params.covariance) {
    const double speed = person.velocity.allFinite() ? person.velocity.norm() : 0.0;
    if (speed >= params.standing_speed && speed > 0.0) {
      c = person.velocity.x() / speed;
      s = person.velocity.y() / speed;
      front_variance = params.covariance * (1.0 + params.factor * speed);
    }
    front_scale = 0.5 / front_variance;
    scale = 0.5 / variance;
  }

  // The exponent at world point p: x^2 / (2 sx^2) + y^2 / (2 sy^2) in the person's frame.
  [[nodiscard]] double exponent(const Eigen::Vector2d& p) const {
    const double dx = p.x() - centre.x();
    const double dy = p.y() - centre.y();
    const double x = c * dx + s * dy;
    const double y = -s * dx + c * dy;
    return x * x * (x > 0.0 ? front_scale : scale) + y * y * scale;
  }
};

// Cell index range whose centres lie in [low, high] along one axis, clamped to [-1, size] first so that a
// far-off person cannot overflow an int.
struct IndexRange {
  int first;
  int last;
};
IndexRange centre_range(double low, double high, double origin, double res, int size) {
  const double first = std::clamp(std::ceil((low - origin) / res - 0.5), -1.0, static_cast<double>(size));
  const double last = std::clamp(std::floor((high - origin) / res - 0.5), -1.0, static_cast<double>(size));
  return {static_cast<int>(first), static_cast<int>(last)};
}

// A value's cell cost: 0 under the cutoff, else floor(value), at most 252 (inline for the stamping loop).
inline std::uint8_t cost_of(double value, double cutoff) {
  if (!(value >= cutoff) || !(value >= 1.0)) return cost::kFree;
  // Positive, so truncation is the floor (and far cheaper than std::floor without SSE4.1); capped first.
  return static_cast<std::uint8_t>(static_cast<int>(std::min(value, cost::kInscribed - 1.0)));
}

}  // namespace

double proxemic_value(const SeenPerson& person, const Eigen::Vector2d& point, const ProxemicLayerParams& params) {
  return params.amplitude * std::exp(-Gaussian(person, params).exponent(point));
}

std::uint8_t proxemic_cost(double value, const ProxemicLayerParams& params) {
  return cost_of(value, params.cutoff);
}

WorldBox proxemic_bounds(const SeenPerson& person, const ProxemicLayerParams& params) {
  if (!person.position.allFinite() || !(params.amplitude > params.cutoff)) return {};
  const Gaussian g(person, params);
  // value >= cutoff  <=>  exponent <= ln(amplitude / cutoff): in front a half ellipse with semi-axes a
  // (along the heading) and b, behind a half disc of radius b.
  const double limit = 2.0 * std::log(params.amplitude / params.cutoff);
  const double a = std::sqrt(limit * g.front_variance);
  const double b = std::sqrt(limit * g.variance);
  // The half ellipse reaches as far as the whole ellipse along an axis where the whole ellipse's extreme
  // point lies in front (u >= 0), else only as far as its flat side, the segment u = 0, |v| <= b. The half
  // disc behind lies in the disc of radius b, and the half ellipse holds the disc's front half, so the
  // union's box is the half ellipse's box joined with the disc's.
  const double reach_x = std::sqrt(a * a * g.c * g.c + b * b * g.s * g.s);
  const double reach_y = std::sqrt(a * a * g.s * g.s + b * b * g.c * g.c);
  const double flat_x = b * std::abs(g.s);
  const double flat_y = b * std::abs(g.c);
  const double max_x = std::max(g.c >= 0.0 ? reach_x : flat_x, b);
  const double min_x = std::min(g.c <= 0.0 ? -reach_x : -flat_x, -b);
  const double max_y = std::max(g.s >= 0.0 ? reach_y : flat_y, b);
  const double min_y = std::min(g.s <= 0.0 ? -reach_y : -flat_y, -b);
  return {g.centre + Eigen::Vector2d(min_x, min_y), g.centre + Eigen::Vector2d(max_x, max_y)};
}

int ProxemicLayer::set_people(std::span<const SeenPerson> people) {
  people_.clear();
  for (const SeenPerson& p : people) {
    if (p.position.allFinite()) people_.push_back(p);
  }
  return static_cast<int>(people_.size());
}

void ProxemicLayer::update_bounds(const CostmapGrid& frame, CellWindow& frame_bounds) {
  CellWindow now = CellWindow::none();
  for (const SeenPerson& p : people_) {
    const WorldBox box = proxemic_bounds(p, params_);
    if (box.empty()) continue;
    const IndexRange cols = centre_range(box.min.x(), box.max.x(), frame.origin_x, frame.resolution, frame.width);
    const IndexRange rows = centre_range(box.min.y(), box.max.y(), frame.origin_y, frame.resolution, frame.height);
    now.include(CellWindow{cols.first, rows.first, cols.last, rows.last});
  }
  frame_bounds.include(now);
  frame_bounds.include(last_bounds_);  // where the last update's people were: their costs must go
  last_bounds_ = now;
}

void ProxemicLayer::stamp(CostmapGrid& grid, const SeenPerson& person, const CellWindow& clip) const {
  WorldBox box = proxemic_bounds(person, params_);
  if (box.empty()) return;
  // A hair of slack, so a centre exactly on the cutoff contour is not lost to rounding.
  box.min.array() -= 1e-9;
  box.max.array() += 1e-9;
  const IndexRange cols = centre_range(box.min.x(), box.max.x(), grid.origin_x, grid.resolution, grid.width);
  const IndexRange rows = centre_range(box.min.y(), box.max.y(), grid.origin_y, grid.resolution, grid.height);
  const CellWindow w =
      CellWindow{cols.first, rows.first, cols.last, rows.last}.intersected(clip).clipped(grid.width, grid.height);
  if (w.empty()) return;
  const Gaussian g(person, params_);
  // Corners of the box fail the cutoff without an exp: compare the exponent with its limit first.
  const double limit = std::log(params_.amplitude / params_.cutoff) + 1e-9;
  const double amplitude = params_.amplitude;
  const double cutoff = params_.cutoff;
  for (int row = w.min_row; row <= w.max_row; ++row) {
    std::uint8_t* out = &grid.costs[grid.index({0, row})];
    for (int col = w.min_col; col <= w.max_col; ++col) {
      const double q = g.exponent(grid.cell_centre({col, row}));
      if (q > limit) continue;
      out[col] = std::max(out[col], cost_of(amplitude * std::exp(-q), cutoff));
    }
  }
}

void ProxemicLayer::update_costs(CostmapGrid& master, CostmapGrid& social, const CellWindow& window) const {
  if (window.empty()) return;
  const int n = window.columns();
  for (int row = window.min_row; row <= window.max_row; ++row) {
    std::uint8_t* cells = &social.costs[social.index({window.min_col, row})];
    std::fill(cells, cells + n, cost::kFree);
  }
  if (people_.empty()) return;
  for (const SeenPerson& p : people_) stamp(social, p, window);
  for (int row = window.min_row; row <= window.max_row; ++row) {
    const std::uint8_t* in = &social.costs[social.index({window.min_col, row})];
    std::uint8_t* out = &master.costs[master.index({window.min_col, row})];
    for (int i = 0; i < n; ++i) out[i] = std::max(out[i], in[i]);
  }
}

}  // namespace rfbsim::sim
