// SPDX-License-Identifier: GPL-2.0-or-later
// build_scene: the world as a list of shapes and a camera. Reads the world, never changes it; no GL here.
#pragma once

#include "render/draw_list.hpp"
#include "render/nav_overlay.hpp"
#include "world/camera_mode.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// How the world is drawn: geometry constants and the optional debug layers.
struct SceneStyle {
  float wall_height = 2.2f;       ///< m
  float avatar_height = 1.75f;    ///< m, top of the head
  bool debug_overlay = false;     ///< draw the robot's plan, trajectory, goal, estimate and social cost
  NavOverlayStyle overlay;        ///< how that overlay looks
  /// A bird's-eye camera straight down over the whole map (sim_replay's top view) instead of the
  /// participant's third-person camera, with a ring under the avatar so that it can be found from above.
  bool top_view = false;
  /// The participant's view when not `top_view`: behind the avatar, or from its eyes without its body.
  CameraMode camera = CameraMode::kThirdPerson;
  float eye_height = 1.62f;  ///< m above the floor: first person's eye (a little under the head's top)
  float top_view_aspect = 16.0f / 9.0f;  ///< the frame's width / height, which the top view fits the map into
};

/// Builds the frame's scene: floor, walls (merged runs), props by kind, landmarks, the robot, the people and
/// the avatar with their gaits and shadows, and a third-person camera behind the avatar at the rig's height.
/// With `style.debug_overlay` and a robot, the navigation overlay (nav_overlay.hpp) follows as the last items;
/// without, the scene is exactly what it is without the overlay code. With `style.top_view` the camera looks
/// straight down on the map's centre (map +y up in the picture), high enough that the whole map and its
/// walls fit a frame of `top_view_aspect`, and there is no fog. With `style.camera` first person (and no top
/// view) the camera is first_person_camera's and the avatar and its shadow are left out.
Scene build_scene(const World& world, const SceneStyle& style = {});

/// The first-person camera of `avatar`: the eye `style.eye_height` above its feet, looking along its yaw,
/// the gaze 10 degrees below the horizon (a walker watches the floor ahead). The rig's height (Up/Down) does not
/// move it.
ViewCamera first_person_camera(const Avatar& avatar, const SceneStyle& style);

/// How one humanoid looks: colours (RGB 0..1) and how broad it is.
struct HumanoidLook {
  Eigen::Vector3f shirt{0.18f, 0.5f, 0.82f};
  Eigen::Vector3f trousers{0.22f, 0.24f, 0.32f};
  Eigen::Vector3f skin{0.86f, 0.68f, 0.55f};
  Eigen::Vector3f hair{0.23f, 0.16f, 0.12f};
  Eigen::Vector3f shoes{0.13f, 0.13f, 0.13f};
  float build = 1.0f;  ///< width factor across the shoulders and hips, 1 = average
};

/// A pedestrian's look: `shirt`, with trousers, skin, hair, shoes and build picked deterministically from `id`.
HumanoidLook humanoid_look(int id, const Eigen::Vector3f& shirt);

/// Appends a walking humanoid whose feet stand at `position`, facing `yaw` (rad); `gait_phase` (rad) swings
/// the arms and legs by `swing` (0 standing .. 1 full stride), `height` (m, top of the head) scales the body.
void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const HumanoidLook& look);
/// The same with the default look in `shirt` colour (the avatar).
void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const Eigen::Vector3f& shirt);

}  // namespace rfbsim::sim
