// SPDX-License-Identifier: GPL-2.0-or-later
// build_scene: floor, walls, props, landmarks, robot, people, avatar, the debug overlay, the camera.
#include "render/scene_builder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "map/grid_map.hpp"
#include "render/scene_parts.hpp"
#include "render/shape_items.hpp"

namespace rfbsim::sim {

namespace {

DrawItem box(const Eigen::Vector3f& centre, const Eigen::Vector3f& size, const Eigen::Vector3f& color,
             Surface surface = Surface::Plain) {
  DrawItem item;
  item.shape = Shape::Box;
  item.surface = surface;
  item.model = Eigen::Translation3f(centre) * Eigen::Scaling(size);
  item.color = color;
  return item;
}

// The top view's camera: straight down on the centre of the map's bounding box (the map may be turned by
// its origin yaw), high enough that the floor and the wall tops fit the frame with a small margin. The eye
// sits a hair south of the target so that look_at's up (world z) stays defined and map +y points up in the
// picture. Fog is pushed out of reach: from up here every distance is "far".
void place_top_camera(Scene& scene, const GridMap& map, const SceneStyle& style) {
  const double map_w = map.width * map.resolution;
  const double map_h = map.height * map.resolution;
  Eigen::Vector2d low = map.to_world({0.0, 0.0});
  Eigen::Vector2d high = low;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(map_w, 0.0), Eigen::Vector2d(0.0, map_h), Eigen::Vector2d(map_w, map_h)}) {
    const Eigen::Vector2d at = map.to_world(corner);
    low = low.cwiseMin(at);
    high = high.cwiseMax(at);
  }
  constexpr float kMargin = 1.04f;       // 4 % of room around the map
  constexpr float kFovDegrees = 40.0f;   // narrow: walls lean out little toward the edges
  constexpr float kHighestEye = 180.0f;  // m: the renderer's far plane is 200 m
  const float aspect = style.top_view_aspect > 0.0f ? style.top_view_aspect : 16.0f / 9.0f;
  const auto half_w = static_cast<float>(high.x() - low.x()) / 2.0f * kMargin;
  const auto half_h = static_cast<float>(high.y() - low.y()) / 2.0f * kMargin;
  const float need = std::max(half_h, half_w / aspect);  // half the view's height at the wall tops, m
  float fov = kFovDegrees;
  float above_walls = need / std::tan(fov * 0.5f * std::numbers::pi_v<float> / 180.0f);
  if (above_walls + style.wall_height > kHighestEye) {  // a huge map: widen the lens rather than clip it
    above_walls = kHighestEye - style.wall_height;
    fov = std::min(120.0f, 2.0f * std::atan(need / above_walls) * 180.0f / std::numbers::pi_v<float>);
  }
  const float eye_height = above_walls + style.wall_height;
  const Eigen::Vector3f centre{static_cast<float>(low.x() + high.x()) / 2.0f, static_cast<float>(low.y() + high.y()) / 2.0f,
                               0.0f};
  scene.camera.eye = centre + Eigen::Vector3f(0.0f, -1e-3f * eye_height, eye_height);
  scene.camera.target = centre;
  scene.camera.fov_y_degrees = fov;
  scene.fog_start = 1e4f;
  scene.fog_end = 2e4f;
}

// A translucent ring in the avatar's colour around its feet: from above, a person is a few pixels wide.
void append_top_view_marker(std::vector<DrawItem>& items, const Eigen::Vector3f& feet, const Eigen::Vector3f& color) {
  DrawItem ring;
  ring.shape = Shape::Disc;
  ring.model = Eigen::Translation3f(feet.x(), feet.y(), 0.012f) * Eigen::Scaling(1.6f, 1.6f, 1.0f);
  ring.color = color;
  ring.opacity = 0.55f;
  items.push_back(ring);
}

}  // namespace

ViewCamera first_person_camera(const Avatar& avatar, const SceneStyle& style) {
  constexpr float kGazeDown = 10.0f * std::numbers::pi_v<float> / 180.0f;
  const auto yaw = static_cast<float>(avatar.pose.yaw);
  ViewCamera camera;
  camera.eye = {static_cast<float>(avatar.pose.x), static_cast<float>(avatar.pose.y), style.eye_height};
  // A target 1 m away along the gaze: look_at needs only the direction.
  camera.target = camera.eye + Eigen::Vector3f(std::cos(kGazeDown) * std::cos(yaw), std::cos(kGazeDown) * std::sin(yaw),
                                               -std::sin(kGazeDown));
  return camera;
}

Scene build_scene(const World& world, const SceneStyle& style) {
  Scene scene;
  const GridMap& map = world.map;
  const auto res = static_cast<float>(map.resolution);
  const auto map_w = static_cast<float>(map.width) * res;
  const auto map_h = static_cast<float>(map.height) * res;
  const Eigen::Vector2d centre = map.to_world({static_cast<double>(map_w) / 2.0, static_cast<double>(map_h) / 2.0});
  const Eigen::AngleAxisf map_turn(static_cast<float>(map.origin_yaw), Eigen::Vector3f::UnitZ());

  // Floor: a thin slab under the whole map.
  DrawItem floor = box({static_cast<float>(centre.x()), static_cast<float>(centre.y()), -0.05f}, {map_w, map_h, 0.1f},
                       rgb(0xc8c2b4), Surface::Floor);
  floor.model = Eigen::Translation3f(static_cast<float>(centre.x()), static_cast<float>(centre.y()), -0.05f) *
                map_turn * Eigen::Scaling(map_w, map_h, 0.1f);
  scene.items.push_back(floor);

  // Walls: one box per merged rectangle of wall cells.
  for (const WallRect& rect : merge_wall_rectangles(map)) {
    const float w = static_cast<float>(rect.columns) * res;
    const float h = static_cast<float>(rect.rows) * res;
    const Eigen::Vector2d at = map.to_world({static_cast<double>(rect.first_column) * map.resolution + static_cast<double>(w) / 2.0,
                                             static_cast<double>(rect.first_row) * map.resolution + static_cast<double>(h) / 2.0});
    DrawItem wall;
    wall.surface = Surface::Wall;
    wall.color = rgb(0xe6e1d6);
    wall.model = Eigen::Translation3f(static_cast<float>(at.x()), static_cast<float>(at.y()), style.wall_height / 2.0f) *
                 map_turn * Eigen::Scaling(w, h, style.wall_height);
    scene.items.push_back(wall);
  }

  // The social world: props by kind, landmarks, the robot and the people, each with its own look.
  for (const Prop& prop : world.props) append_prop(scene.items, prop);
  for (const Landmark& landmark : world.landmarks) append_landmark(scene.items, landmark);
  if (world.robot) append_robot(scene.items, *world.robot);
  for (const Person& person : world.people) append_person(scene.items, person);

  // The avatar, and a soft shadow under it that anchors it to the floor; not in first person, where the
  // camera sits inside its head and its body would fill the picture.
  const Avatar& avatar = world.avatar;
  const Eigen::Vector3f feet{static_cast<float>(avatar.pose.x), static_cast<float>(avatar.pose.y), 0.0f};
  const auto yaw = static_cast<float>(avatar.pose.yaw);
  const bool first_person = !style.top_view && style.camera == CameraMode::kFirstPerson;
  if (!first_person) {
    const float swing = std::min(1.0f, static_cast<float>(std::abs(avatar.speed)) / 1.3f);
    append_humanoid(scene.items, feet, yaw, static_cast<float>(avatar.gait_phase), swing, style.avatar_height,
                    rgb(0x2f7fd0));
    append_soft_shadow(scene.items, feet.x(), feet.y(), 0.4f);
  }

  // From above, a ring marks the avatar (the participant view has none).
  if (style.top_view) append_top_view_marker(scene.items, feet, rgb(0x2f7fd0));

  // The navigation overlay last: its translucent squares then blend over the shadows and the floor.
  if (style.debug_overlay && world.robot) append_nav_overlay(scene.items, *world.robot, style.overlay);

  if (style.top_view) {
    place_top_camera(scene, map, style);
    return scene;
  }
  if (first_person) {
    scene.camera = first_person_camera(avatar, style);
    return scene;
  }

  // Third-person camera: behind the avatar at the rig's height, looking at its chest a little ahead.
  // It comes closer rather than pass through a wall or a tall shelf behind the avatar.
  const Eigen::Vector3f heading{std::cos(yaw), std::sin(yaw), 0.0f};
  const GridMap& solid = world.obstacles.width > 0 ? world.obstacles : map;
  const auto distance = static_cast<float>(solid.free_distance(avatar.pose.x, avatar.pose.y, -std::cos(avatar.pose.yaw),
                                                             -std::sin(avatar.pose.yaw), world.camera.distance, 0.15));
  scene.camera.eye = feet - heading * distance + Eigen::Vector3f(0.0f, 0.0f, static_cast<float>(world.camera.height));
  scene.camera.target = feet + heading * 1.0f + Eigen::Vector3f(0.0f, 0.0f, 1.1f);
  return scene;
}

}  // namespace rfbsim::sim
