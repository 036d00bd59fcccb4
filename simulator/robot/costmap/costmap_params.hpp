// SPDX-License-Identifier: GPL-2.0-or-later
// Parameters of the layered costmap and of each layer, with ROS's names where ROS has one and the
// defaults of docs/sources.md (costmap_2d, social_navigation_layers, SEAN's Kuri).
#pragma once

namespace rfbsim::sim {

/// The obstacle layer: what a lidar scan marks and clears (costmap_2d's ObstacleLayer).
struct ObstacleLayerParams {
  double obstacle_range = 2.5;  ///< m: returns at most this far from the sensor are marked lethal
  double raytrace_range = 3.0;  ///< m: each beam clears the cells it crosses up to this far
};

/// The inflation layer: costs falling off around lethal cells (costmap_2d's InflationLayer).
struct InflationLayerParams {
  double inflation_radius = 0.3;     ///< m: cells farther than this from every lethal cell stay free
  double cost_scaling_factor = 3.0;  ///< 1/m: how fast the cost falls beyond the inscribed radius
};

/// The proxemic layer: a Gaussian of cost around each person (Lu, Hershberger, Smart 2014).
struct ProxemicLayerParams {
  double amplitude = 77.0;      ///< cost at the person's centre
  double covariance = 0.25;     ///< m^2: variance behind and beside a person (SEAN used 0.1)
  double cutoff = 10.0;         ///< cells whose cost would be below this are left alone
  double factor = 5.0;          ///< s/m: in front, the variance is covariance * (1 + factor * speed)
  double standing_speed = 0.05; ///< m/s: slower than this a person is a circle (no front, no back)
};

/// One costmap: its extent (global or rolling), which layers it runs and their parameters.
struct CostmapParams {
  double resolution = 0.05;     ///< m per cell
  bool rolling_window = false;  ///< false: the static map's bounding box (global); true: a window on the robot
  double width = 4.0;           ///< m, rolling window only
  double height = 4.0;          ///< m, rolling window only
  double robot_radius = 0.16;   ///< m: the footprint (never marked) and the inscribed radius (cost 253)
  bool use_static_layer = true;     ///< the static map's walls and props, lethal
  bool use_obstacle_layer = true;   ///< the lidar's marks, lethal
  bool use_inflation_layer = true;  ///< costs around every lethal cell
  bool use_proxemic_layer = true;   ///< personal space around the people the caller passes
  ObstacleLayerParams obstacle;    ///< obstacle_range, raytrace_range
  InflationLayerParams inflation;  ///< inflation_radius, cost_scaling_factor
  ProxemicLayerParams proxemic;    ///< amplitude, covariance, cutoff, factor
};

/// Kuri's global costmap (docs/sources.md): the whole map, inflation 0.3 m.
CostmapParams global_costmap_params();
/// Kuri's local costmap: a width x height m window on the robot, inflation `inflation_radius` m
/// (SEAN's Kuri used 0.1 m).
CostmapParams local_costmap_params(double inflation_radius = 0.1, double width = 4.0, double height = 4.0);

/// Throws std::invalid_argument naming the first field that is out of range (e.g. "costmap: resolution
/// must be a positive finite number of metres, got 0").
void validate(const CostmapParams& params);

}  // namespace rfbsim::sim
