// SPDX-License-Identifier: GPL-2.0-or-later
// DwaParams: the DWA local planner's settings, with ROS dwa_local_planner's names and (mostly) defaults.
#pragma once

namespace rfbsim::sim {

/// The DWA local planner's settings (ROS dwa_local_planner names; where the default differs from ROS's,
/// the comment says why).
struct DwaParams {
  // Velocity limits.
  double max_vel_x = 0.3;      ///< m/s, fastest forward (SEAN-EP ran Kuri at 0.3; Kuri's limit is 0.5)
  double min_vel_x = 0.0;      ///< m/s, slowest sampled (negative lets the robot back up)
  double max_vel_theta = 1.0;  ///< rad/s, fastest turn either way (Kuri can do 3)
  double min_vel_theta = 0.0;  ///< rad/s: with |v| below min_vel_trans, turns slower than this are not sampled
                               ///< (ROS's motor dead band, 0.4 there; a simulated base has none)
  double min_vel_trans = 0.1;  ///< m/s: slower counts as turning in place (dead band and oscillation flags)
  double acc_lim_x = 1.0;      ///< m/s^2
  double acc_lim_theta = 2.0;  ///< rad/s^2

  // Forward simulation.
  double sim_time = 1.7;                 ///< s each rollout is simulated with constant (v, w)
  double sim_granularity = 0.025;        ///< m between rollout points along the way
  double angular_sim_granularity = 0.1;  ///< rad between rollout points when turning
  int vx_samples = 6;    ///< speeds sampled across the window (ROS 3: at 10 Hz the window is only 0.2 m/s
                         ///< wide, and 6 samples resolve it to 0.02 m/s for little cost)
  int vth_samples = 20;  ///< turn rates sampled across the window (plus 0 when the window spans it)
  double controller_frequency = 10.0;  ///< Hz: compute() is called this often; the window is +-acc / frequency
  double stop_time_buffer = 0.2;  ///< s: each rollout is checked for obstacles this much longer than sim_time

  // Scoring: cost = path * path distance (m) + goal * goal distance (m) + occdist * max cell cost (0..252).
  // dwa_local_planner's defaults, 32 and 24 (it scales them by the resolution and measures in cells: per
  // metre that is 32 and 24). docs/sources.md's 0.6 and 0.8 are base_local_planner's pdist_scale and
  // gdist_scale, which weigh cells, not metres; taken per metre they let a cell of cost 200 outweigh 2.5 m
  // of distance, and the robot stalled turning in place at inner corners.
  double path_distance_bias = 32.0;     ///< weight per m between a rollout's end and the global path
  double goal_distance_bias = 24.0;     ///< weight per m between a rollout's end and the local goal
  double occdist_scale = 0.1;           ///< weight per unit of the highest cell cost along a rollout
  double forward_point_distance = 0.325;  ///< m: the "nose" point ahead of a rollout's end, kept on the path

  // People (rfbsim: the people critic, dwa_people_critic.hpp).
  double robot_radius = 0.16;      ///< m, the body the people critic keeps clear (the stack sets the robot's)
  double people_clearance = 0.1;   ///< m kept between the robot's and a person's bodies, people predicted ahead
  double people_horizon = 1.0;     ///< s of constant-velocity prediction; 0 switches the critic off
  /// m kept between the bodies while the robot itself moves toward a walking person (issue 19): within
  /// this gap a rollout may stop, turn, move aside or away, but not close in on someone who walks. 0.45 m
  /// puts a 0.25 m person's centre 0.86 m from Kuri's: outside Hall's intimate zone by a margin, at the
  /// near edge of the personal zone. Standing people are the proxemic layer's (the robot must be able to
  /// pass someone waiting in an aisle); 0 switches the rule off (the behaviour before issue 19).
  double people_personal_clearance = 0.45;
  /// m/s: people at least this fast walk, for the rule above. 0.5 m/s is the slowest walking speed the
  /// crowd draws (docs/sources.md: libpedsim's clamp); someone slower is waiting or turning, and the robot must
  /// still be able to pass them (0.1 m/s: the robot dithered where people mill about the storage gate, and
  /// lost its localization doing so in 2 of 50 trials, against 1 with 0.5).
  double people_walking_speed = 0.5;

  // Oscillation suppression.
  double oscillation_reset_dist = 0.05;   ///< m the robot must move before a reversed turn is allowed again
  double oscillation_reset_angle = 0.2;   ///< rad the robot must turn before the same
};

}  // namespace rfbsim::sim
