// SPDX-License-Identifier: GPL-2.0-or-later
// Amcl: Monte Carlo localization in the style of ROS's amcl (docs/sources.md, Localization): a particle filter
// over the robot's pose with the odometry motion model and the likelihood-field laser model, updated only
// after the robot moved update_min_d or turned update_min_a, resampled by low-variance sampling.
//
// Where rfbsim differs from ROS amcl, and why:
//   - A fixed particle count (`particles`, default 500, kept within [min_particles, max_particles]); no
//     KLD-sampling, so that the cost per update is known (the robot stack has a 15 ms budget). As in ROS,
//     the initial cloud has max_particles (5000): with 500, the first scan, much sharper than the 0.5 m
//     wide prior, found no particle near the truth and the cloud collapsed 0.2-0.3 m off. The first
//     resampling brings the count down to `particles`.
//   - No recovery by random particles (recovery_alpha_slow/fast are 0 in ROS too) and no global
//     localization: the study starts the robot where the scenario says.
//   - Beam likelihoods are multiplied (summed as logs), as in Probabilistic Robotics (table 6.3), with the
//     Gaussian's normalisation; ROS's likelihood_field model sums their cubes instead (1 + sum p^3, an ad
//     hoc smoothing). In our 8 x 6 m test room the cube sum kept the cloud 0.3 m wide and ended up to
//     0.14 m off; the product converges to 2-3 cm and the motion noise (alpha 0.2) keeps it from collapsing.
//   - The estimate is the weighted mean of all particles (circular mean for yaw), not the mean of the
//     heaviest cluster: the filter starts near the truth, so the cloud is one cluster.
//   - The update test uses the straight distance moved (ROS tests |dx| and |dy| separately).
//   - A scan with no usable beam (all range_max) applies the motion but neither weighs nor resamples, so
//     that an empty scan does not thin out the particles for nothing.
#pragma once

#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "map/grid_map.hpp"
#include "robot/sensing/laser_scan.hpp"
#include "robot/sensing/likelihood_field.hpp"
#include "robot/sensing/motion_delta.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// How the beams' likelihoods combine into a particle's weight (ROS's laser_model_type, where it has one).
enum class LaserModel {
  LikelihoodField,         ///< ROS amcl: 1 + sum of p^3 (robust to beams hitting things not on the map)
  LikelihoodFieldProduct,  ///< the textbook product of the beams' normalised likelihoods (sharper)
};

/// AMCL's parameters, with ROS amcl's names and defaults.
struct AmclParams {
  int min_particles = 100;   ///< lower bound for `particles`
  int max_particles = 5000;  ///< upper bound for `particles`, and the initial cloud's size (as ROS)
  int particles = 500;       ///< rfbsim: the particle count after resampling (no KLD-sampling)
  double odom_alpha1 = 0.2;  ///< rotation noise from rotation (variance per rad^2 turned)
  double odom_alpha2 = 0.2;  ///< rotation noise from translation (rad^2 per m^2)
  double odom_alpha3 = 0.2;  ///< translation noise from translation (variance per m^2 driven)
  double odom_alpha4 = 0.2;  ///< translation noise from rotation (m^2 per rad^2)
  double laser_z_hit = 0.95;                ///< weight of the Gaussian around the nearest obstacle
  double laser_z_rand = 0.05;               ///< weight of uniform random readings over [0, range_max]
  double laser_sigma_hit = 0.2;             ///< m, stddev of the hit Gaussian
  double laser_likelihood_max_dist = 2.0;   ///< m, the distance field's cap
  int laser_max_beams = 30;                 ///< beams used per update, spread evenly over the scan
  LaserModel laser_model_type = LaserModel::LikelihoodFieldProduct;  ///< how the beams combine
  /// Skip beams that too few particles explain (ROS's do_beamskip; off there by default, on here: in a
  /// crowd many beams hit people, whom the map does not hold).
  bool do_beamskip = true;
  double beam_skip_distance = 0.5;         ///< m: an endpoint this near an obstacle agrees with the map
  double beam_skip_threshold = 0.3;        ///< a beam is kept when at least this share of particles agree
  double beam_skip_error_threshold = 0.9;  ///< skipping more than this share of beams means lost: keep all
  double update_min_d = 0.2;                ///< m driven before a filter update
  double update_min_a = std::numbers::pi / 6;  ///< rad turned before a filter update
  int resample_interval = 1;                ///< filter updates (with a usable scan) between resamplings
  double initial_cov_xx = 0.25;             ///< m^2, initial spread in x
  double initial_cov_yy = 0.25;             ///< m^2, initial spread in y
  double initial_cov_aa = (std::numbers::pi / 12) * (std::numbers::pi / 12);  ///< rad^2, initial spread in yaw
};

/// One pose hypothesis and its normalised weight.
struct Particle {
  Pose2 pose;
  double weight = 0.0;
};

/// The localization filter. Holds its own copy of the likelihood field; the map is not kept.
class Amcl {
 public:
  /// `map`: what the lidar sees of the world (World::obstacles: walls and props). max_particles particles
  /// are drawn from N(initial, diag(initial_cov_xx, initial_cov_yy, initial_cov_aa)). Throws
  /// std::invalid_argument, naming the parameter, on parameters no filter can run with (no particles,
  /// sigma_hit <= 0, negative alphas, a non-finite pose, a map without a positive resolution).
  Amcl(const GridMap& map, AmclParams params, Pose2 initial, std::uint64_t seed);

  /// Feeds the odometry pose now and, if not null, the scan taken now (at the robot's centre). The filter
  /// updates (motion, then weighing and resampling) on a call with a scan once the odometry moved
  /// update_min_d or turned update_min_a since the last filter update, and on the first call with a scan.
  /// Returns whether the filter updated. A non-finite odometry pose is ignored (returns false).
  bool update(const Pose2& odom_pose, const LaserScan* scan);

  /// Re-draws the particles around `initial` (as at construction) and forgets the odometry reference.
  void reset(Pose2 initial);

  /// The pose estimate now: the filter's weighted mean at its last update, moved on by the odometry's
  /// motion since, so that it follows the robot smoothly between filter updates (m, m, rad).
  [[nodiscard]] Pose2 estimate() const;
  /// The weighted mean at the last filter update (without the odometry since).
  [[nodiscard]] const Pose2& filter_estimate() const { return filter_estimate_; }
  /// The particles after the last filter update (weights sum to 1): max_particles of them until the first
  /// resampling, `particles` after.
  [[nodiscard]] const std::vector<Particle>& particles() const { return particles_; }
  /// Weighted stddev of the particles' positions about their mean, sqrt(var x + var y), m.
  [[nodiscard]] double position_stddev() const;
  /// Circular stddev of the particles' yaws, sqrt(-2 ln R), rad.
  [[nodiscard]] double yaw_stddev() const;
  /// Filter updates done since construction (reset() does not clear it).
  [[nodiscard]] int filter_updates() const { return filter_updates_; }
  [[nodiscard]] const AmclParams& params() const { return params_; }

 private:
  void draw_particles(const Pose2& initial);
  void apply_motion(const MotionDelta& delta);
  /// Weighs the particles by the scan; false if the scan had no usable beam (weights untouched).
  bool apply_scan(const LaserScan& scan);
  void resample();
  void update_estimate();
  void rebuild_log_likelihood(double range_max);

  AmclParams params_;
  LikelihoodField field_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_gaussian_{0.0, 1.0};
  std::vector<Particle> particles_;
  std::vector<Particle> scratch_;  // resampling target, swapped with particles_
  std::vector<double> log_weights_;
  std::vector<Eigen::Vector2d> beam_ends_;  // the chosen beams' endpoints in the sensor frame, m
  // The field's distances as whole squared cell counts (exact: the distance transform's values are
  // sqrt(integer) cells), so that the beam model is a table of (max_dist / resolution)^2 + 1 entries
  // (1601 by default), rebuilt in microseconds when range_max changes.
  std::vector<std::uint32_t> distance_keys_;  // per cell
  std::uint32_t outside_key_ = 0;             // the cap's key: endpoints off the map
  std::vector<double> log_likelihood_;        // per key: log(z_hit N(d) + z_rand / range_max)
  std::vector<std::uint32_t> beam_keys_;     // per particle and chosen beam: the endpoint's distance key
  std::vector<std::uint8_t> beam_used_;      // per chosen beam: 1 unless skipped
  std::vector<double> cubed_likelihood_;      // per key: (z_hit exp(-d^2 / 2 sigma^2) + z_rand / range_max)^3
  double log_likelihood_range_max_ = -1.0;    // the range_max the table was built for
  bool has_odom_ = false;
  Pose2 filter_odom_;    // odometry pose at the last filter update
  Pose2 latest_odom_;    // odometry pose at the last call
  Pose2 filter_estimate_;
  bool sensed_ = false;  // whether any filter update ran since the particles were drawn
  int filter_updates_ = 0;
  int resample_count_ = 0;
};

}  // namespace rfbsim::sim
