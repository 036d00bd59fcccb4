// SPDX-License-Identifier: GPL-2.0-or-later
// The robot's simulated 2D lidar: beams cast through the obstacle grid and against the round bodies of
// people and the avatar, with Gaussian range noise. Also the geometry every scan consumer needs (which
// beams are returns, where they hit), so that costmaps and AMCL read a scan the same way.
//
// Scan layout (rfbsim's choice, as Hokuyo-style ROS drivers do): beams are spread evenly over the field of
// view centred on the heading, angle_min = -fov / 2, counter-clockwise. For a full circle the increment is
// 2 pi / beams and no beam is repeated, so with 360 beams beam 0 points straight back (-pi), beam 90 to the
// right, beam 180 straight ahead and beam 270 to the left. For a partial fov both edges are beams:
// increment fov / (beams - 1).
//
// Ranges (what a ROS consumer of sensor_msgs/LaserScan expects):
//   - a beam that hits nothing within range_max reads exactly range_max (as a float);
//   - a return reads its distance plus N(0, noise_stddev), clamped to [range_min, range_max): noise never
//     turns a return into a "no return" nor pushes it below range_min;
//   - a return nearer than range_min reads range_min: the obstacle is there, only nearer than the sensor
//     can measure, and a costmap that marks it at range_min errs on the safe side (a real lidar would read
//     garbage or nothing, which would hide the obstacle). The lidar inside a wall cell, outside the map or
//     inside a body therefore reads range_min on every beam it cannot see out of.
//   - a pose that is not finite gives a scan with no returns (every beam range_max).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "map/grid_map.hpp"
#include "robot/sensing/laser_scan.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// The lidar's model (docs/sources.md, SEAN's Kuri robot: TurtleBot3-like 360 beams, sigma 0.01 m).
struct LidarParams {
  int beams = 360;                      ///< beams per sweep, >= 1
  double fov = 6.283185307179586;       ///< rad, field of view (2 pi: all round)
  double range_min = 0.12;              ///< m, nearer returns read range_min
  /// m. Longer than TurtleBot3's 3.5 m (a Hokuyo-class sensor): the warehouse's aisles are 30 m long and
  /// AMCL needs walls in view to localize, which 3.5 m would often not give.
  double range_max = 8.0;
  double rate_hz = 10.0;                ///< sweeps per second (the caller decides when to cast)
  double noise_stddev = 0.01;           ///< m, Gaussian range noise on returns
  double mount_height = 0.214;          ///< m above the floor; only for drawing the beams
};

/// A round body the lidar sees: a person or the avatar, as a circle on the floor plane.
struct LidarBody {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< m, world frame
  double radius = 0.25;                              ///< m
};

/// Every body the robot's lidar sees in `world`: each person and the avatar, with their radii (never the
/// robot itself). Clears `out` first; reuse it across calls to avoid reallocation.
void collect_lidar_bodies(const World& world, std::vector<LidarBody>& out);

/// The same, as a fresh vector.
[[nodiscard]] std::vector<LidarBody> lidar_bodies(const World& world);

/// The first beam's angle against the heading in scans laid out by `params` (-fov / 2), rad.
[[nodiscard]] double lidar_angle_min(const LidarParams& params);
/// The angle between neighbouring beams in scans laid out by `params` (see the top of this file), rad.
[[nodiscard]] double lidar_angle_increment(const LidarParams& params);

/// Throws std::invalid_argument naming the field if `params` cannot describe a lidar (beams < 1, fov not
/// in (0, 2 pi], range_min < 0, range_max <= range_min, noise_stddev < 0, or anything not finite).
void check_lidar_params(const LidarParams& params);

/// One sweep from `sensor` (the lidar sits at the robot's centre, facing its heading) at `time` s: each
/// beam reads the nearest of the grid ray cast through `obstacles` and the bodies; noise from `rng` is
/// added to returns only (see the top of this file for the ranges' rules). Throws std::invalid_argument
/// on bad params (check_lidar_params).
[[nodiscard]] LaserScan cast_scan(const GridMap& obstacles, std::span<const LidarBody> bodies,
                                  const Pose2& sensor, double time, const LidarParams& params,
                                  std::mt19937_64& rng);

/// The same, writing into `scan` so its range buffer is reused (no allocation once sized).
void cast_scan_into(LaserScan& scan, const GridMap& obstacles, std::span<const LidarBody> bodies,
                    const Pose2& sensor, double time, const LidarParams& params, std::mt19937_64& rng);

/// Distance along a ray from `origin` in the unit direction `dir` to where it enters the circle, m;
/// 0 if the origin is inside it; nullopt if it misses or the circle lies behind.
[[nodiscard]] std::optional<double> ray_circle_distance(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir,
                                                        const LidarBody& body);

/// Whether `range` (a value from scan.ranges) is a return: finite, >= range_min and below range_max
/// (compared as floats, as the ranges are stored).
[[nodiscard]] bool is_return(const LaserScan& scan, float range);

/// Angle of beam `beam` against the sensor's heading, rad.
[[nodiscard]] inline double beam_angle(const LaserScan& scan, int beam) {
  return scan.angle_min + beam * scan.angle_increment;
}

/// World point hit by beam `beam` when the scan was taken at `sensor`, or nullopt if the beam index is out
/// of range or the beam is not a return.
[[nodiscard]] std::optional<Eigen::Vector2d> scan_point(const LaserScan& scan, int beam, const Pose2& sensor);

}  // namespace rfbsim::sim
