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
  // metre that is 32 and 24). REFERENCE.md's 0.6 and 0.8 are base_local_planner's pdist_scale and
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

  // Oscillation suppression.
  double oscillation_reset_dist = 0.05;   ///< m the robot must move before a reversed turn is allowed again
  double oscillation_reset_angle = 0.2;   ///< rad the robot must turn before the same
};

}  // namespace rfbsim::sim
