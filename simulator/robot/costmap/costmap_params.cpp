// SPDX-License-Identifier: GPL-2.0-or-later
// Costmap parameter presets and their range checks.
#include "robot/costmap/costmap_params.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rfbsim::sim {

CostmapParams global_costmap_params() { return CostmapParams{}; }

CostmapParams local_costmap_params(double inflation_radius, double width, double height) {
  CostmapParams params;
  params.rolling_window = true;
  params.width = width;
  params.height = height;
  params.inflation.inflation_radius = inflation_radius;
  return params;
}

namespace {

// Throws unless `value` is finite and at least `lowest` (or above it when `strict`).
void check(double value, double lowest, bool strict, const char* name, const char* unit) {
  const bool ok = std::isfinite(value) && (strict ? value > lowest : value >= lowest);
  if (ok) return;
  throw std::invalid_argument(std::string("costmap: ") + name + " must be a finite number " +
                              (strict ? "above " : "of at least ") + std::to_string(lowest) + unit + ", got " +
                              std::to_string(value));
}

}  // namespace

void validate(const CostmapParams& p) {
  check(p.resolution, 0.0, true, "resolution", " m");
  if (p.rolling_window) {
    check(p.width, p.resolution, false, "width", " m");
    check(p.height, p.resolution, false, "height", " m");
    // A window beyond 20000 cells a side is a units mistake, and would not fit an int's cell count.
    if (p.width / p.resolution > 20000.0 || p.height / p.resolution > 20000.0) {
      throw std::invalid_argument("costmap: width and height must be at most 20000 cells (" +
                                  std::to_string(p.width) + " x " + std::to_string(p.height) + " m at " +
                                  std::to_string(p.resolution) + " m)");
    }
  }
  check(p.robot_radius, 0.0, false, "robot_radius", " m");
  check(p.obstacle.obstacle_range, 0.0, false, "obstacle_range", " m");
  check(p.obstacle.raytrace_range, 0.0, false, "raytrace_range", " m");
  check(p.inflation.inflation_radius, 0.0, false, "inflation_radius", " m");
  check(p.inflation.cost_scaling_factor, 0.0, false, "cost_scaling_factor", " 1/m");
  check(p.proxemic.amplitude, 0.0, false, "proxemic amplitude", "");
  check(p.proxemic.covariance, 0.0, true, "proxemic covariance", " m^2");
  check(p.proxemic.cutoff, 0.0, true, "proxemic cutoff", "");
  check(p.proxemic.factor, 0.0, false, "proxemic factor", " s/m");
  check(p.proxemic.standing_speed, 0.0, false, "proxemic standing_speed", " m/s");
}

}  // namespace rfbsim::sim
