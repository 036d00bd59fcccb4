// SPDX-License-Identifier: GPL-2.0-or-later
// The simulated lidar: one exact grid traversal per beam, the nearest body hit, then noise on returns.
#include "robot/sensing/lidar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robot/sensing/motion_delta.hpp"

namespace rfbsim::sim {

namespace {

// A full circle, up to rounding in how the caller wrote 2 pi.
bool is_full_circle(double fov) { return fov >= 2.0 * std::numbers::pi - 1e-9; }

void require_lidar(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("LidarParams: ") + what);
}

// Whether the world point lies on the grid, without casting a huge or NaN coordinate to int.
bool on_grid(const GridMap& map, double x, double y) {
  const Eigen::Vector2d p = map.to_map_frame(x, y);
  return p.x() >= 0.0 && p.y() >= 0.0 && p.x() < map.width * map.resolution && p.y() < map.height * map.resolution;
}

}  // namespace

void collect_lidar_bodies(const World& world, std::vector<LidarBody>& out) {
  out.clear();
  for (const Person& person : world.people) out.push_back({{person.pose.x, person.pose.y}, person.radius});
  out.push_back({{world.avatar.pose.x, world.avatar.pose.y}, world.avatar.radius});
}

std::vector<LidarBody> lidar_bodies(const World& world) {
  std::vector<LidarBody> bodies;
  collect_lidar_bodies(world, bodies);
  return bodies;
}

double lidar_angle_min(const LidarParams& params) { return -0.5 * params.fov; }

double lidar_angle_increment(const LidarParams& params) {
  if (is_full_circle(params.fov)) return params.fov / params.beams;
  return params.beams > 1 ? params.fov / (params.beams - 1) : 0.0;
}

void check_lidar_params(const LidarParams& params) {
  require_lidar(params.beams >= 1, "beams must be at least 1");
  require_lidar(std::isfinite(params.fov) && params.fov > 0.0 && params.fov <= 2.0 * std::numbers::pi + 1e-9,
          "fov must be in (0, 2 pi] rad");
  require_lidar(std::isfinite(params.range_min) && params.range_min >= 0.0, "range_min must be >= 0 m");
  require_lidar(std::isfinite(params.range_max) && params.range_max > params.range_min,
          "range_max must be finite and above range_min");
  require_lidar(std::isfinite(params.noise_stddev) && params.noise_stddev >= 0.0, "noise_stddev must be >= 0 m");
}

std::optional<double> ray_circle_distance(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir,
                                          const LidarBody& body) {
  const Eigen::Vector2d to_centre = body.centre - origin;
  const double radius_sq = body.radius * body.radius;
  const double centre_sq = to_centre.squaredNorm();
  if (centre_sq <= radius_sq) return 0.0;
  const double along = to_centre.dot(dir);
  if (along <= 0.0) return std::nullopt;
  const double miss_sq = centre_sq - along * along;
  if (miss_sq >= radius_sq) return std::nullopt;
  return along - std::sqrt(radius_sq - miss_sq);
}

LaserScan cast_scan(const GridMap& obstacles, std::span<const LidarBody> bodies, const Pose2& sensor,
                    double time, const LidarParams& params, std::mt19937_64& rng) {
  LaserScan scan;
  cast_scan_into(scan, obstacles, bodies, sensor, time, params, rng);
  return scan;
}

void cast_scan_into(LaserScan& scan, const GridMap& obstacles, std::span<const LidarBody> bodies,
                    const Pose2& sensor, double time, const LidarParams& params, std::mt19937_64& rng) {
  check_lidar_params(params);
  scan.time = time;
  scan.angle_min = lidar_angle_min(params);
  scan.angle_increment = lidar_angle_increment(params);
  scan.range_min = params.range_min;
  scan.range_max = params.range_max;
  const auto beam_count = static_cast<std::size_t>(params.beams);
  const auto no_return = static_cast<float>(params.range_max);
  scan.ranges.assign(beam_count, no_return);
  if (!is_finite_pose(sensor)) return;

  // Off the grid the lidar is inside "wall" (outside the map blocks): it sees nothing beyond range_min.
  const bool inside_map = on_grid(obstacles, sensor.x, sensor.y);
  const Eigen::Vector2d origin(sensor.x, sensor.y);
  // The largest float below range_max: where noise may push a return without making it a "no return".
  const float below_max = std::nextafter(no_return, 0.0F);
  const auto min_range = static_cast<float>(params.range_min);
  std::normal_distribution<double> unit_gaussian(0.0, 1.0);

  for (std::size_t i = 0; i < beam_count; ++i) {
    const double angle = sensor.yaw + scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    // The grid: an exact traversal up to range_max (0 when the lidar stands in a blocking cell).
    double range = inside_map ? obstacles.ray_cast(sensor.x, sensor.y, angle, params.range_max) : 0.0;
    // The bodies: the nearest circle entry in front of the lidar, if nearer than the wall.
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    for (const LidarBody& body : bodies) {
      if (!(body.radius > 0.0) || !body.centre.allFinite()) continue;
      const std::optional<double> hit = ray_circle_distance(origin, dir, body);
      if (hit && *hit < range) range = *hit;
    }
    if (range >= params.range_max) continue;  // no return: stays exactly range_max, no noise
    if (params.noise_stddev > 0.0) range += params.noise_stddev * unit_gaussian(rng);
    scan.ranges[i] = std::clamp(static_cast<float>(range), min_range, below_max);
  }
}

bool is_return(const LaserScan& scan, float range) {
  return std::isfinite(range) && range >= static_cast<float>(scan.range_min) &&
         range < static_cast<float>(scan.range_max);
}

std::optional<Eigen::Vector2d> scan_point(const LaserScan& scan, int beam, const Pose2& sensor) {
  if (beam < 0 || static_cast<std::size_t>(beam) >= scan.ranges.size()) return std::nullopt;
  const float stored = scan.ranges[static_cast<std::size_t>(beam)];
  if (!is_return(scan, stored) || !is_finite_pose(sensor)) return std::nullopt;
  const auto range = static_cast<double>(stored);
  const double angle = sensor.yaw + beam_angle(scan, beam);
  return Eigen::Vector2d(sensor.x + range * std::cos(angle), sensor.y + range * std::sin(angle));
}

}  // namespace rfbsim::sim
