// SPDX-License-Identifier: GPL-2.0-or-later
// SeenPerson: a person the robot perceives (in line of sight of its lidar, within range), as a people
// tracker would report them: where they are and how they move. What the proxemic layer works from.
#pragma once

#include <Eigen/Core>

namespace rfbsim::sim {

struct SeenPerson {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< m, world frame
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, world frame
  double radius = 0.25;                                ///< m, body radius
};

}  // namespace rfbsim::sim
