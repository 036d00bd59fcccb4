// SPDX-License-Identifier: GPL-2.0-or-later
// build_scene: the world as a list of shapes and a camera. Reads the world, never changes it; no GL here.
#pragma once

#include "render/draw_list.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// Geometry constants of the drawn world.
struct SceneStyle {
  float wall_height = 2.2f;       ///< m
  float avatar_height = 1.75f;    ///< m, top of the head
};

/// Builds the frame's scene: floor, walls (merged runs), props, the avatar with its gait, its shadow, and a
/// third-person camera behind the avatar at the rig's height.
Scene build_scene(const World& world, const SceneStyle& style = {});

/// Appends a walking humanoid standing at `pose`, facing its yaw, in `shirt` colour; `gait_phase` in radians
/// swings the arms and legs, `height` scales the whole body.
void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const Eigen::Vector3f& shirt);

}  // namespace rfbsim::sim
