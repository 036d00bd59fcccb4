// SPDX-License-Identifier: GPL-2.0-or-later
// LaserScan: one sweep of the robot's 2D lidar, laid out as ROS's sensor_msgs/LaserScan (beam i points at
// angle_min + i * angle_increment in the sensor frame, counter-clockwise from the sensor's heading).
#pragma once

#include <vector>

namespace rfbsim::sim {

struct LaserScan {
  double time = 0.0;             ///< simulated seconds when the sweep was taken
  double angle_min = 0.0;        ///< rad, first beam against the sensor's heading
  double angle_increment = 0.0;  ///< rad between neighbouring beams
  double range_min = 0.12;       ///< m: nearer returns are invalid
  double range_max = 3.5;        ///< m: a beam that hit nothing reads exactly range_max
  std::vector<float> ranges;     ///< m per beam; range_max = no return
};

}  // namespace rfbsim::sim
