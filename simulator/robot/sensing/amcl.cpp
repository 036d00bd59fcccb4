// SPDX-License-Identifier: GPL-2.0-or-later
// Amcl: drawing, moving, weighing and resampling the particles, and the estimate between updates.
#include "robot/sensing/amcl.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "robot/sensing/lidar.hpp"

namespace rfbsim::sim {

namespace {

void require_amcl(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("AmclParams: ") + what);
}

bool non_negative(double v) { return std::isfinite(v) && v >= 0.0; }

// AMCL ignores the direction of travel for drives shorter than this, m.
constexpr double kMinTrans = 0.01;

}  // namespace

Amcl::Amcl(const GridMap& map, AmclParams params, Pose2 initial, std::uint64_t seed)
    : params_(params), rng_(seed) {
  require_amcl(params.min_particles >= 1 && params.max_particles >= params.min_particles,
          "need 1 <= min_particles <= max_particles");
  params_.particles = std::clamp(params.particles, params.min_particles, params.max_particles);
  require_amcl(non_negative(params.odom_alpha1) && non_negative(params.odom_alpha2) &&
              non_negative(params.odom_alpha3) && non_negative(params.odom_alpha4),
          "odom_alpha1..4 must be >= 0");
  require_amcl(non_negative(params.laser_z_hit) && non_negative(params.laser_z_rand) &&
              params.laser_z_hit + params.laser_z_rand > 0.0,
          "laser_z_hit and laser_z_rand must be >= 0, not both 0");
  require_amcl(std::isfinite(params.laser_sigma_hit) && params.laser_sigma_hit > 0.0, "laser_sigma_hit must be > 0 m");
  require_amcl(params.laser_max_beams >= 1, "laser_max_beams must be >= 1");
  require_amcl(non_negative(params.update_min_d) && non_negative(params.update_min_a),
          "update_min_d and update_min_a must be >= 0");
  require_amcl(params.resample_interval >= 1, "resample_interval must be >= 1");
  require_amcl(non_negative(params.initial_cov_xx) && non_negative(params.initial_cov_yy) &&
              non_negative(params.initial_cov_aa),
          "initial_cov_xx, _yy and _aa must be >= 0");
  if (!(map.resolution > 0.0) || !std::isfinite(map.resolution)) {
    throw std::invalid_argument("Amcl: the map's resolution must be a positive number of metres");
  }
  // The field checks laser_likelihood_max_dist.
  field_ = LikelihoodField(map, params.laser_likelihood_max_dist);
  const double cap_cells = params.laser_likelihood_max_dist / map.resolution;
  require_amcl(cap_cells < 4096.0, "laser_likelihood_max_dist must be under 4096 map cells");
  const auto key_of = [&map](double metres) {
    const double cells = metres / map.resolution;
    return static_cast<std::uint32_t>(std::lround(cells * cells));
  };
  outside_key_ = key_of(params.laser_likelihood_max_dist);
  distance_keys_.resize(field_.distances().size());
  std::transform(field_.distances().begin(), field_.distances().end(), distance_keys_.begin(),
                 [&](float d) { return std::min(key_of(static_cast<double>(d)), outside_key_); });
  particles_.reserve(static_cast<std::size_t>(params_.max_particles));
  scratch_.reserve(static_cast<std::size_t>(params_.max_particles));
  log_weights_.reserve(static_cast<std::size_t>(params_.max_particles));
  beam_ends_.reserve(static_cast<std::size_t>(params.laser_max_beams));
  reset(initial);
}

void Amcl::reset(Pose2 initial) {
  if (!is_finite_pose(initial)) throw std::invalid_argument("Amcl: the initial pose must be finite");
  draw_particles(initial);
  has_odom_ = false;
  sensed_ = false;
  resample_count_ = 0;
}

void Amcl::draw_particles(const Pose2& initial) {
  const double sx = std::sqrt(params_.initial_cov_xx);
  const double sy = std::sqrt(params_.initial_cov_yy);
  const double sa = std::sqrt(params_.initial_cov_aa);
  // As ROS amcl's pf_init: the wide initial cloud gets max_particles, so that some land near the truth
  // before the sharp laser model first weighs them; resampling then keeps `particles`.
  const double weight = 1.0 / params_.max_particles;
  particles_.clear();
  for (int i = 0; i < params_.max_particles; ++i) {
    // Three draws in a fixed order, so the cloud is the same for a seed whatever the covariances.
    const double x = initial.x + sx * unit_gaussian_(rng_);
    const double y = initial.y + sy * unit_gaussian_(rng_);
    const double yaw = normalize_angle(initial.yaw + sa * unit_gaussian_(rng_));
    particles_.push_back({{x, y, yaw}, weight});
  }
  filter_estimate_ = initial;
  filter_estimate_.yaw = normalize_angle(initial.yaw);
}

bool Amcl::update(const Pose2& odom_pose, const LaserScan* scan) {
  if (!is_finite_pose(odom_pose)) return false;
  if (!has_odom_) {
    filter_odom_ = odom_pose;
    has_odom_ = true;
  }
  latest_odom_ = odom_pose;
  // Updates are driven by scans, as ROS amcl's are; without one the estimate follows the odometry.
  if (scan == nullptr) return false;
  const MotionDelta delta = decompose_motion(filter_odom_, odom_pose, kMinTrans);
  const bool moved = std::hypot(odom_pose.x - filter_odom_.x, odom_pose.y - filter_odom_.y) >= params_.update_min_d ||
                     std::abs(normalize_angle(odom_pose.yaw - filter_odom_.yaw)) >= params_.update_min_a;
  if (sensed_ && !moved) return false;

  apply_motion(delta);
  filter_odom_ = odom_pose;
  sensed_ = true;
  ++filter_updates_;
  const bool weighed = apply_scan(*scan);
  // The estimate comes from the weighted cloud, before resampling flattens the weights.
  update_estimate();
  if (weighed && ++resample_count_ % params_.resample_interval == 0) resample();
  return true;
}

void Amcl::apply_motion(const MotionDelta& delta) {
  // sample_motion_model_odometry (Probabilistic Robotics, table 5.6): each particle moves by the odometry's
  // rot1, trans, rot2, each perturbed with a variance from the alphas. trans is signed (backwards < 0) and
  // |rot1| <= pi/2, which is ROS's min(|rot1|, |pi - rot1|) for the noise.
  const double rot1_sq = delta.rot1 * delta.rot1;
  const double rot2_sq = delta.rot2 * delta.rot2;
  const double trans_sq = delta.trans * delta.trans;
  const double sd_rot1 = std::sqrt(params_.odom_alpha1 * rot1_sq + params_.odom_alpha2 * trans_sq);
  const double sd_trans = std::sqrt(params_.odom_alpha3 * trans_sq + params_.odom_alpha4 * (rot1_sq + rot2_sq));
  const double sd_rot2 = std::sqrt(params_.odom_alpha1 * rot2_sq + params_.odom_alpha2 * trans_sq);
  for (Particle& particle : particles_) {
    MotionDelta noisy = delta;
    noisy.rot1 += sd_rot1 * unit_gaussian_(rng_);
    noisy.trans += sd_trans * unit_gaussian_(rng_);
    noisy.rot2 += sd_rot2 * unit_gaussian_(rng_);
    particle.pose = compose_motion(particle.pose, noisy);
  }
}

void Amcl::rebuild_log_likelihood(double range_max) {
  // p(z) = z_hit N(d; 0, sigma_hit) + z_rand / range_max for an endpoint d metres from the nearest obstacle,
  // tabulated per distance key whenever the scans' range_max changes.
  const double sigma = params_.laser_sigma_hit;
  const double norm = 1.0 / (sigma * std::sqrt(2.0 * std::numbers::pi));
  const double floor = params_.laser_z_rand / range_max;
  const double resolution = field_.geometry().resolution;
  log_likelihood_.resize(static_cast<std::size_t>(outside_key_) + 1);
  cubed_likelihood_.resize(log_likelihood_.size());
  for (std::size_t key = 0; key < log_likelihood_.size(); ++key) {
    const double d = std::min(std::sqrt(static_cast<double>(key)) * resolution, field_.max_dist());
    const double gaussian = std::exp(-0.5 * d * d / (sigma * sigma));
    const double p = params_.laser_z_hit * norm * gaussian + floor;
    log_likelihood_[key] = std::log(std::max(p, std::numeric_limits<double>::min()));
    // ROS's form: no normalisation, so p stays within [0, 1] and its cube is a bounded vote per beam.
    const double vote = params_.laser_z_hit * gaussian + floor;
    cubed_likelihood_[key] = vote * vote * vote;
  }
  log_likelihood_range_max_ = range_max;
}

bool Amcl::apply_scan(const LaserScan& scan) {
  // laser_max_beams beams spread evenly over the scan (ROS's step), skipping non-returns.
  const int count = static_cast<int>(scan.ranges.size());
  if (count == 0 || !(scan.range_max > 0.0) || !std::isfinite(scan.range_max)) return false;
  const int step = params_.laser_max_beams > 1 ? std::max(1, (count - 1) / (params_.laser_max_beams - 1)) : count;
  beam_ends_.clear();
  for (int beam = 0; beam < count && static_cast<int>(beam_ends_.size()) < params_.laser_max_beams; beam += step) {
    const float stored = scan.ranges[static_cast<std::size_t>(beam)];
    if (!is_return(scan, stored)) continue;
    const auto range = static_cast<double>(stored);
    const double angle = beam_angle(scan, beam);
    beam_ends_.emplace_back(range * std::cos(angle), range * std::sin(angle));
  }
  if (beam_ends_.empty()) return false;
  if (scan.range_max != log_likelihood_range_max_) rebuild_log_likelihood(scan.range_max);

  // Endpoints go straight into the grid's frame: world = particle (+) beam end, then the map's inverse pose.
  const GridMap& grid = field_.geometry();
  const double cos_map = std::cos(grid.origin_yaw);
  const double sin_map = std::sin(grid.origin_yaw);
  const double inv_res = 1.0 / grid.resolution;
  log_weights_.resize(particles_.size());
  // Pass 1: every chosen beam's endpoint, seen from every particle, as a distance key (the cap's key off
  // the map).
  const std::size_t beams = beam_ends_.size();
  beam_keys_.resize(particles_.size() * beams);
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Pose2& pose = particles_[i].pose;
    const double c = std::cos(pose.yaw);
    const double s = std::sin(pose.yaw);
    // The particle's position and axes in the grid's frame, in cells.
    const double dx = pose.x - grid.origin_x;
    const double dy = pose.y - grid.origin_y;
    const double gx = (cos_map * dx + sin_map * dy) * inv_res;
    const double gy = (-sin_map * dx + cos_map * dy) * inv_res;
    const double ax = (cos_map * c + sin_map * s) * inv_res;  // the particle's +x axis in grid cells per m
    const double ay = (-sin_map * c + cos_map * s) * inv_res;
    for (std::size_t b = 0; b < beams; ++b) {
      const Eigen::Vector2d& end = beam_ends_[b];
      const double u = gx + ax * end.x() - ay * end.y();
      const double v = gy + ay * end.x() + ax * end.y();
      const bool inside = u >= 0.0 && v >= 0.0 && u < grid.width && v < grid.height;
      beam_keys_[i * beams + b] =
          inside ? distance_keys_[static_cast<std::size_t>(v) * static_cast<std::size_t>(grid.width) +
                                  static_cast<std::size_t>(u)]
                 : outside_key_;
    }
  }
  // Beam skipping (ROS amcl's do_beamskip): a beam whose endpoint lies near an obstacle for too few
  // particles most likely hit something the map does not hold (a person), and is left out; unless that
  // would leave out nearly all beams, when the filter is lost and needs them all.
  beam_used_.assign(beams, 1);
  if (params_.do_beamskip && particles_.size() > 0) {
    const double near_cells = params_.beam_skip_distance / grid.resolution;
    const auto near_key = static_cast<std::uint32_t>(near_cells * near_cells);
    std::size_t skipped = 0;
    for (std::size_t b = 0; b < beams; ++b) {
      std::size_t agree = 0;
      for (std::size_t i = 0; i < particles_.size(); ++i) agree += beam_keys_[i * beams + b] <= near_key ? 1U : 0U;
      if (static_cast<double>(agree) < params_.beam_skip_threshold * static_cast<double>(particles_.size())) {
        beam_used_[b] = 0;
        ++skipped;
      }
    }
    if (static_cast<double>(skipped) > params_.beam_skip_error_threshold * static_cast<double>(beams)) {
      beam_used_.assign(beams, 1);
    }
  }
  // Pass 2: each particle's weight from the beams kept.
  const bool product = params_.laser_model_type == LaserModel::LikelihoodFieldProduct;
  const std::vector<double>& table = product ? log_likelihood_ : cubed_likelihood_;
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    double sum = 0.0;
    for (std::size_t b = 0; b < beams; ++b) {
      if (beam_used_[b]) sum += table[beam_keys_[i * beams + b]];
    }
    // Product: the sum of logs. ROS: the weight is multiplied by 1 + the sum of the cubes.
    if (!product) sum = std::log1p(sum);
    log_weights_[i] = std::log(std::max(particles_[i].weight, std::numeric_limits<double>::min())) + sum;
    best = std::max(best, log_weights_[i]);
  }
  // Normalise in log space: thirty beam likelihoods multiply to 1e-66 and less, and weights carried over
  // several updates (resample_interval > 1) would underflow.
  double total = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].weight = std::exp(log_weights_[i] - best);
    total += particles_[i].weight;
  }
  for (Particle& particle : particles_) particle.weight /= total;
  return true;
}

void Amcl::resample() {
  // Low-variance (systematic) resampling: one random offset, then N evenly spaced pointers into the
  // cumulative weights (Probabilistic Robotics, table 4.4).
  // From however many particles there are (max_particles after a reset) to the fixed count.
  const std::size_t n = static_cast<std::size_t>(params_.particles);
  const double spacing = 1.0 / static_cast<double>(n);
  std::uniform_real_distribution<double> offset(0.0, spacing);
  double pointer = offset(rng_);
  double cumulative = particles_[0].weight;
  std::size_t source = 0;
  scratch_.clear();
  for (std::size_t m = 0; m < n; ++m) {
    while (pointer > cumulative && source + 1 < particles_.size()) cumulative += particles_[++source].weight;
    scratch_.push_back({particles_[source].pose, spacing});
    pointer += spacing;
  }
  particles_.swap(scratch_);
}

void Amcl::update_estimate() {
  double x = 0.0;
  double y = 0.0;
  double sin_sum = 0.0;
  double cos_sum = 0.0;
  for (const Particle& particle : particles_) {
    x += particle.weight * particle.pose.x;
    y += particle.weight * particle.pose.y;
    sin_sum += particle.weight * std::sin(particle.pose.yaw);
    cos_sum += particle.weight * std::cos(particle.pose.yaw);
  }
  filter_estimate_ = {x, y, std::atan2(sin_sum, cos_sum)};
}

Pose2 Amcl::estimate() const {
  if (!has_odom_) return filter_estimate_;
  // The odometry's motion since the last filter update, in its own frame, applied to the filter's pose.
  return compose_motion(filter_estimate_, decompose_motion(filter_odom_, latest_odom_, 0.0));
}

double Amcl::position_stddev() const {
  double mx = 0.0;
  double my = 0.0;
  for (const Particle& particle : particles_) {
    mx += particle.weight * particle.pose.x;
    my += particle.weight * particle.pose.y;
  }
  double variance = 0.0;
  for (const Particle& particle : particles_) {
    const double dx = particle.pose.x - mx;
    const double dy = particle.pose.y - my;
    variance += particle.weight * (dx * dx + dy * dy);
  }
  return std::sqrt(variance);
}

double Amcl::yaw_stddev() const {
  double sin_sum = 0.0;
  double cos_sum = 0.0;
  for (const Particle& particle : particles_) {
    sin_sum += particle.weight * std::sin(particle.pose.yaw);
    cos_sum += particle.weight * std::cos(particle.pose.yaw);
  }
  const double resultant = std::min(1.0, std::hypot(sin_sum, cos_sum));
  return resultant > 0.0 ? std::sqrt(-2.0 * std::log(resultant)) : std::numbers::pi;
}

}  // namespace rfbsim::sim
