// SPDX-License-Identifier: GPL-2.0-or-later
// parse_robot_params: a table of every settable robot parameter, its section, its ROS name and its range.
#include "scenario/robot_params_yaml.hpp"

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace rfbsim::sim {

namespace {

constexpr double kBig = std::numeric_limits<double>::max();

/// One settable parameter: where it lives and what values it takes.
struct Setting {
  const char* section;
  const char* key;
  std::variant<double*, int*, bool*> field;
  double low = 0.0;
  double high = kBig;
};

std::vector<Setting> settings(RobotParams& p) {
  CostmapParams& g = p.global_costmap;
  CostmapParams& l = p.local_costmap;
  return {
      // The base (docs/sources.md: Kuri).
      {"drive", "max_vel_x", &p.drive.max_vel_x, 0.0, 5.0},
      {"drive", "min_vel_x", &p.drive.min_vel_x, -5.0, 0.0},
      {"drive", "max_vel_theta", &p.drive.max_vel_theta, 0.1, 20.0},
      {"drive", "acc_lim_x", &p.drive.acc_lim_x, 0.01, 50.0},
      {"drive", "acc_lim_theta", &p.drive.acc_lim_theta, 0.01, 100.0},
      {"drive", "footprint_padding", &p.footprint_padding, 0.0, 1.0},
      // Sensors.
      {"lidar", "beams", &p.lidar.beams, 1, 4096},
      {"lidar", "fov", &p.lidar.fov, 0.01, 6.283185307179586},
      {"lidar", "range_min", &p.lidar.range_min, 0.0, 100.0},
      {"lidar", "range_max", &p.lidar.range_max, 0.1, 100.0},
      {"lidar", "rate", &p.lidar.rate_hz, 0.5, 100.0},
      {"lidar", "noise_stddev", &p.lidar.noise_stddev, 0.0, 1.0},
      {"odometry", "trans_stddev_per_m", &p.odometry.trans_stddev_per_m, 0.0, 1.0},
      {"odometry", "trans_stddev_per_rad", &p.odometry.trans_stddev_per_rad, 0.0, 1.0},
      {"odometry", "rot_stddev_per_rad", &p.odometry.rot_stddev_per_rad, 0.0, 1.0},
      {"odometry", "rot_stddev_per_m", &p.odometry.rot_stddev_per_m, 0.0, 1.0},
      {"odometry", "trans_scale_error", &p.odometry.trans_scale_error, -0.5, 0.5},
      {"odometry", "rot_scale_error", &p.odometry.rot_scale_error, -0.5, 0.5},
      {"odometry", "yaw_drift_per_m", &p.odometry.yaw_drift_per_m, -1.0, 1.0},
      // Localization (ROS amcl names).
      {"amcl", "particles", &p.amcl.particles, 1, 100000},
      {"amcl", "min_particles", &p.amcl.min_particles, 1, 100000},
      {"amcl", "max_particles", &p.amcl.max_particles, 1, 100000},
      {"amcl", "odom_alpha1", &p.amcl.odom_alpha1, 0.0, 10.0},
      {"amcl", "odom_alpha2", &p.amcl.odom_alpha2, 0.0, 10.0},
      {"amcl", "odom_alpha3", &p.amcl.odom_alpha3, 0.0, 10.0},
      {"amcl", "odom_alpha4", &p.amcl.odom_alpha4, 0.0, 10.0},
      {"amcl", "laser_z_hit", &p.amcl.laser_z_hit, 0.0, 1.0},
      {"amcl", "laser_z_rand", &p.amcl.laser_z_rand, 0.0, 1.0},
      {"amcl", "laser_sigma_hit", &p.amcl.laser_sigma_hit, 0.001, 10.0},
      {"amcl", "laser_likelihood_max_dist", &p.amcl.laser_likelihood_max_dist, 0.01, 100.0},
      {"amcl", "laser_max_beams", &p.amcl.laser_max_beams, 1, 4096},
      {"amcl", "do_beamskip", &p.amcl.do_beamskip},
      {"amcl", "beam_skip_distance", &p.amcl.beam_skip_distance, 0.0, 10.0},
      {"amcl", "beam_skip_threshold", &p.amcl.beam_skip_threshold, 0.0, 1.0},
      {"amcl", "beam_skip_error_threshold", &p.amcl.beam_skip_error_threshold, 0.0, 1.0},
      {"amcl", "update_min_d", &p.amcl.update_min_d, 0.0, 100.0},
      {"amcl", "update_min_a", &p.amcl.update_min_a, 0.0, 6.283185307179586},
      {"amcl", "resample_interval", &p.amcl.resample_interval, 1, 1000},
      {"amcl", "initial_cov_xx", &p.amcl.initial_cov_xx, 0.0, 100.0},
      {"amcl", "initial_cov_yy", &p.amcl.initial_cov_yy, 0.0, 100.0},
      {"amcl", "initial_cov_aa", &p.amcl.initial_cov_aa, 0.0, 100.0},
      // Costmaps (costmap_2d and social_navigation_layers names).
      {"global_costmap", "update_frequency", &p.global_update_frequency, 0.1, 100.0},
      {"global_costmap", "inflation_radius", &g.inflation.inflation_radius, 0.0, 10.0},
      {"global_costmap", "cost_scaling_factor", &g.inflation.cost_scaling_factor, 0.0, 100.0},
      {"global_costmap", "obstacle_range", &g.obstacle.obstacle_range, 0.0, 100.0},
      {"global_costmap", "raytrace_range", &g.obstacle.raytrace_range, 0.0, 100.0},
      {"global_costmap", "obstacle_layer", &g.use_obstacle_layer},
      {"global_costmap", "proxemic_layer", &g.use_proxemic_layer},
      {"local_costmap", "width", &l.width, 0.5, 50.0},
      {"local_costmap", "height", &l.height, 0.5, 50.0},
      {"local_costmap", "inflation_radius", &l.inflation.inflation_radius, 0.0, 10.0},
      {"local_costmap", "cost_scaling_factor", &l.inflation.cost_scaling_factor, 0.0, 100.0},
      {"local_costmap", "obstacle_range", &l.obstacle.obstacle_range, 0.0, 100.0},
      {"local_costmap", "raytrace_range", &l.obstacle.raytrace_range, 0.0, 100.0},
      {"local_costmap", "proxemic_layer", &l.use_proxemic_layer},
      // The proxemic layer's Gaussian, the same in both costmaps (set below).
      {"proxemic", "amplitude", &g.proxemic.amplitude, 0.0, 252.0},
      {"proxemic", "covariance", &g.proxemic.covariance, 0.001, 100.0},
      {"proxemic", "cutoff", &g.proxemic.cutoff, 0.0, 252.0},
      {"proxemic", "factor", &g.proxemic.factor, 0.0, 100.0},
      // Global planner (ROS global_planner names).
      {"global_planner", "neutral_cost", &p.planner.neutral_cost, 1.0, 252.0},
      {"global_planner", "cost_factor", &p.planner.cost_factor, 0.0, 100.0},
      {"global_planner", "use_dijkstra", &p.planner.use_dijkstra},
      {"global_planner", "default_tolerance", &p.planner.default_tolerance, 0.0, 10.0},
      // move_base.
      {"move_base", "controller_frequency", &p.navigator.controller_frequency, 1.0, 60.0},
      {"move_base", "planner_frequency", &p.navigator.planner_frequency, 0.0, 60.0},
      {"move_base", "planner_patience", &p.navigator.planner_patience, 0.0, 600.0},
      {"move_base", "controller_patience", &p.navigator.controller_patience, 0.0, 600.0},
      {"move_base", "oscillation_timeout", &p.navigator.oscillation_timeout, 0.0, 3600.0},
      {"move_base", "oscillation_distance", &p.navigator.oscillation_distance, 0.0, 100.0},
      {"move_base", "recovery_behavior_enabled", &p.navigator.recovery_behavior_enabled},
      {"move_base", "conservative_reset_dist", &p.navigator.conservative_reset_dist, 0.0, 100.0},
      {"move_base", "aggressive_reset_dist", &p.navigator.aggressive_reset_dist, 0.0, 100.0},
      {"move_base", "xy_goal_tolerance", &p.navigator.xy_goal_tolerance, 0.01, 10.0},
      {"move_base", "yaw_goal_tolerance", &p.navigator.yaw_goal_tolerance, 0.01, 10.0},
      {"move_base", "waypoint_pause", &p.navigator.waypoint_pause, 0.0, 3600.0},
      {"move_base", "rotate_to_path_angle", &p.navigator.rotate_to_path_angle, 0.2, 3.15},
      // rfbsim: the goal that is a person (docs/scenarios.md); below 0.45 m would be Hall's intimate zone.
      {"move_base", "person_goal_distance", &p.navigator.person_goal_distance, 0.45, 10.0},
      {"move_base", "person_goal_standing_speed", &p.navigator.person_goal_standing_speed, 0.0, 5.0},
      // DWA local planner (ROS dwa_local_planner names).
      {"dwa", "max_vel_x", &p.dwa.max_vel_x, 0.0, 5.0},
      {"dwa", "min_vel_x", &p.dwa.min_vel_x, -5.0, 5.0},
      {"dwa", "max_vel_theta", &p.dwa.max_vel_theta, 0.1, 20.0},
      {"dwa", "min_vel_theta", &p.dwa.min_vel_theta, 0.0, 20.0},
      {"dwa", "min_vel_trans", &p.dwa.min_vel_trans, 0.0, 5.0},
      {"dwa", "acc_lim_x", &p.dwa.acc_lim_x, 0.01, 50.0},
      {"dwa", "acc_lim_theta", &p.dwa.acc_lim_theta, 0.01, 100.0},
      {"dwa", "sim_time", &p.dwa.sim_time, 0.1, 10.0},
      {"dwa", "sim_granularity", &p.dwa.sim_granularity, 0.005, 1.0},
      {"dwa", "angular_sim_granularity", &p.dwa.angular_sim_granularity, 0.01, 1.0},
      {"dwa", "vx_samples", &p.dwa.vx_samples, 1, 100},
      {"dwa", "vth_samples", &p.dwa.vth_samples, 1, 200},
      {"dwa", "stop_time_buffer", &p.dwa.stop_time_buffer, 0.0, 5.0},
      {"dwa", "path_distance_bias", &p.dwa.path_distance_bias, 0.0, 1000.0},
      {"dwa", "goal_distance_bias", &p.dwa.goal_distance_bias, 0.0, 1000.0},
      {"dwa", "occdist_scale", &p.dwa.occdist_scale, 0.0, 1000.0},
      {"dwa", "forward_point_distance", &p.dwa.forward_point_distance, 0.0, 5.0},
      {"dwa", "people_clearance", &p.dwa.people_clearance, 0.0, 5.0},
      {"dwa", "people_horizon", &p.dwa.people_horizon, 0.0, 10.0},
      {"dwa", "people_personal_clearance", &p.dwa.people_personal_clearance, 0.0, 5.0},
      {"dwa", "people_walking_speed", &p.dwa.people_walking_speed, 0.05, 5.0},
      {"dwa", "oscillation_reset_dist", &p.dwa.oscillation_reset_dist, 0.0, 10.0},
      {"dwa", "oscillation_reset_angle", &p.dwa.oscillation_reset_angle, 0.0, 10.0},
  };
}

void apply(const Setting& setting, const YamlField& value) {
  if (auto* number = std::get_if<double*>(&setting.field)) {
    **number = value.number(setting.low, setting.high);
  } else if (auto* integer = std::get_if<int*>(&setting.field)) {
    **integer = value.integer(static_cast<int>(setting.low), static_cast<int>(setting.high));
  } else {
    *std::get<bool*>(setting.field) = value.boolean();
  }
}

}  // namespace

void parse_robot_params(const YamlField& nav, RobotParams& params) {
  const std::vector<Setting> table = settings(params);
  std::vector<std::string> sections;
  for (const Setting& s : table) {
    if (sections.empty() || sections.back() != s.section) sections.emplace_back(s.section);
  }
  sections.emplace_back("localization");
  nav.allow_only(sections);
  if (auto localization = nav.optional("localization")) {
    const std::string kind = localization->text();
    if (kind == "amcl") {
      params.localization = Localization::Amcl;
    } else if (kind == "ground_truth") {
      params.localization = Localization::GroundTruth;
    } else {
      localization->fail("amcl or ground_truth");
    }
  }
  for (const std::string& section : sections) {
    if (section == "localization") continue;
    auto group = nav.optional(section);
    if (!group) continue;
    std::vector<std::string> keys;
    for (const Setting& s : table) {
      if (s.section == section) keys.emplace_back(s.key);
    }
    group->allow_only(keys);
    for (const Setting& s : table) {
      if (s.section != section) continue;
      if (auto value = group->optional(s.key)) apply(s, *value);
    }
  }
  // One proxemic model for both costmaps; the layer's on/off stays per costmap.
  params.local_costmap.proxemic = params.global_costmap.proxemic;
  // Parameters that are each in range but cannot work together.
  try {
    validate(params.global_costmap);
    validate(params.local_costmap);
    check_lidar_params(params.lidar);
    if (const std::string error = dwa_params_error(params.dwa); !error.empty()) throw std::invalid_argument(error);
    if (params.amcl.min_particles > params.amcl.max_particles) {
      throw std::invalid_argument("amcl.min_particles must not exceed amcl.max_particles");
    }
    // DWA plans within the wheels' limits, or it would plan motions the base cannot make.
    if (params.dwa.max_vel_x > params.drive.max_vel_x || params.dwa.min_vel_x < params.drive.min_vel_x ||
        params.dwa.max_vel_theta > params.drive.max_vel_theta || params.dwa.acc_lim_x > params.drive.acc_lim_x ||
        params.dwa.acc_lim_theta > params.drive.acc_lim_theta) {
      throw std::invalid_argument("dwa's velocity and acceleration limits must lie within drive's");
    }
  } catch (const std::invalid_argument& error) {
    nav.fail_with(error.what());
  }
  // The local planner tests the robot's centre cell against inscribed cost: inflation must reach past the
  // robot's radius there, or the body could graze walls and people.
  const CostmapParams& local = params.local_costmap;
  const double footprint = local.robot_radius + params.footprint_padding;
  if (local.use_inflation_layer && local.inflation.inflation_radius < footprint) {
    nav.fail_with("local_costmap.inflation_radius must be at least the robot's padded radius (" +
                  std::to_string(footprint).substr(0, 4) + " m): the local planner checks the robot's "
                  "centre against inflated cost");
  }
}

}  // namespace rfbsim::sim
