// SPDX-License-Identifier: GPL-2.0-or-later
// build_scene: floor, walls, props, avatar, camera.
#include "render/scene_builder.hpp"

#include <algorithm>
#include <cmath>

#include "map/grid_map.hpp"

namespace rfbsim::sim {

namespace {

Eigen::Vector3f rgb(std::uint32_t hex) {
  return {static_cast<float>((hex >> 16) & 0xff) / 255.0f, static_cast<float>((hex >> 8) & 0xff) / 255.0f,
          static_cast<float>(hex & 0xff) / 255.0f};
}

DrawItem box(const Eigen::Vector3f& centre, const Eigen::Vector3f& size, const Eigen::Vector3f& color,
             Surface surface = Surface::Plain) {
  DrawItem item;
  item.shape = Shape::Box;
  item.surface = surface;
  item.model = Eigen::Translation3f(centre) * Eigen::Scaling(size);
  item.color = color;
  return item;
}

// A limb hanging from `pivot` (in the body frame) swung by `angle` about the body's y axis.
DrawItem limb(const Eigen::Affine3f& body, const Eigen::Vector3f& pivot, float angle, const Eigen::Vector3f& size,
              const Eigen::Vector3f& color) {
  DrawItem item;
  item.shape = Shape::Box;
  item.model = body * Eigen::Translation3f(pivot) * Eigen::AngleAxisf(angle, Eigen::Vector3f::UnitY()) *
               Eigen::Translation3f(0.0f, 0.0f, -size.z() / 2.0f) * Eigen::Scaling(size);
  item.color = color;
  return item;
}

}  // namespace

void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const Eigen::Vector3f& shirt) {
  const float s = height / 1.75f;  // proportions below are for a 1.75 m person
  const Eigen::Affine3f body =
      Eigen::Translation3f(position) * Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()) * Eigen::Scaling(s);
  const Eigen::Vector3f trousers{0.22f, 0.24f, 0.32f};
  const Eigen::Vector3f skin{0.86f, 0.68f, 0.55f};
  const float leg = 0.6f * swing * std::sin(gait_phase);
  const float bob = 0.03f * swing * std::abs(std::cos(gait_phase));

  items.push_back(limb(body, {0.0f, 0.1f, 0.9f + bob}, leg, {0.14f, 0.13f, 0.88f}, trousers));
  items.push_back(limb(body, {0.0f, -0.1f, 0.9f + bob}, -leg, {0.14f, 0.13f, 0.88f}, trousers));
  DrawItem torso;
  torso.model = body * Eigen::Translation3f(0.0f, 0.0f, 1.2f + bob) * Eigen::Scaling(0.24f, 0.42f, 0.62f);
  torso.color = shirt;
  items.push_back(torso);
  // Arms swing against the legs, as in a natural walk.
  items.push_back(limb(body, {0.0f, 0.27f, 1.48f + bob}, -0.8f * leg, {0.1f, 0.1f, 0.62f}, shirt));
  items.push_back(limb(body, {0.0f, -0.27f, 1.48f + bob}, 0.8f * leg, {0.1f, 0.1f, 0.62f}, shirt));
  DrawItem head;
  head.shape = Shape::Sphere;
  head.model = body * Eigen::Translation3f(0.0f, 0.0f, 1.63f + bob) * Eigen::Scaling(0.24f);
  head.color = skin;
  items.push_back(head);
  // A nose-like marker shows which way the person faces, even from behind and above.
  DrawItem nose;
  nose.model = body * Eigen::Translation3f(0.12f, 0.0f, 1.62f + bob) * Eigen::Scaling(0.06f, 0.05f, 0.05f);
  nose.color = skin * 0.8f;
  items.push_back(nose);
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

  for (const Prop& prop : world.props) {
    const auto height = static_cast<float>(prop.height);
    scene.items.push_back(box({static_cast<float>(prop.x), static_cast<float>(prop.y), height / 2.0f},
                              {static_cast<float>(prop.size_x), static_cast<float>(prop.size_y), height}, rgb(prop.rgb)));
  }

  // The avatar, and a soft shadow under it that anchors it to the floor.
  const Avatar& avatar = world.avatar;
  const Eigen::Vector3f feet{static_cast<float>(avatar.pose.x), static_cast<float>(avatar.pose.y), 0.0f};
  const auto yaw = static_cast<float>(avatar.pose.yaw);
  const float swing = std::min(1.0f, static_cast<float>(std::abs(avatar.speed)) / 1.3f);
  append_humanoid(scene.items, feet, yaw, static_cast<float>(avatar.gait_phase), swing, style.avatar_height,
                  rgb(0x2f7fd0));
  DrawItem shadow;
  shadow.shape = Shape::Disc;
  shadow.model = Eigen::Translation3f(feet + Eigen::Vector3f(0.0f, 0.0f, 0.01f)) * Eigen::Scaling(0.8f);
  shadow.color = {0.0f, 0.0f, 0.0f};
  shadow.opacity = 0.35f;
  scene.items.push_back(shadow);

  // Third-person camera: behind the avatar at the rig's height, looking at its chest a little ahead.
  // It comes closer rather than pass through a wall behind the avatar.
  const Eigen::Vector3f heading{std::cos(yaw), std::sin(yaw), 0.0f};
  const auto distance = static_cast<float>(map.free_distance(avatar.pose.x, avatar.pose.y, -std::cos(avatar.pose.yaw),
                                                             -std::sin(avatar.pose.yaw), world.camera.distance, 0.15));
  scene.camera.eye = feet - heading * distance + Eigen::Vector3f(0.0f, 0.0f, static_cast<float>(world.camera.height));
  scene.camera.target = feet + heading * 1.0f + Eigen::Vector3f(0.0f, 0.0f, 1.1f);
  return scene;
}

}  // namespace rfbsim::sim
