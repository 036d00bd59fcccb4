// SPDX-License-Identifier: GPL-2.0-or-later
// Landmarks (a floor ring and a tall pole with a ball) and the robot's stand-in (a white rounded body).
#include <algorithm>
#include <cmath>

#include "render/scene_parts.hpp"
#include "render/shape_items.hpp"

namespace rfbsim::sim {

void append_landmark(std::vector<DrawItem>& items, const Landmark& landmark) {
  const Eigen::Vector3f c = rgb(landmark.rgb);
  const Eigen::Affine3f at(Eigen::Translation3f(static_cast<float>(landmark.x), static_cast<float>(landmark.y), 0.0f));
  const float d = 2.0f * static_cast<float>(landmark.radius);
  // A ring: the coloured disc with a paler centre, just above the floor.
  items.push_back(shape_item(Shape::Disc, at, {0.0f, 0.0f, 0.004f}, {d, d, 1.0f}, c));
  items.push_back(shape_item(Shape::Disc, at, {0.0f, 0.0f, 0.006f}, {0.65f * d, 0.65f * d, 1.0f},
                             0.5f * c + Eigen::Vector3f::Constant(0.5f)));
  // The pole rises above the 2.2 m walls, so that the goal shows over them from across the map.
  constexpr float pole = 2.8f;
  items.push_back(shape_item(Shape::Cylinder, at, {0.0f, 0.0f, 0.03f}, {0.2f, 0.2f, 0.06f}, c * 0.5f));
  items.push_back(shape_item(Shape::Cylinder, at, {0.0f, 0.0f, pole / 2.0f}, {0.06f, 0.06f, pole}, c * 0.85f));
  items.push_back(shape_item(Shape::Sphere, at, {0.0f, 0.0f, pole + 0.12f}, Eigen::Vector3f::Constant(0.3f), c));
}

void append_robot(std::vector<DrawItem>& items, const Robot& robot) {
  const auto x = static_cast<float>(robot.pose.x);
  const auto y = static_cast<float>(robot.pose.y);
  const Eigen::Affine3f frame = Eigen::Translation3f(x, y, 0.0f) *
                                Eigen::AngleAxisf(static_cast<float>(robot.pose.yaw), Eigen::Vector3f::UnitZ());
  const auto r = static_cast<float>(robot.radius);
  const float h = std::max(static_cast<float>(robot.height), 2.5f * r);  // room for a body under the dome
  const Eigen::Vector3f white{0.93f, 0.93f, 0.91f};
  const Eigen::Vector3f dark{0.16f, 0.17f, 0.19f};
  const float head_z = h - r;  // the dome's centre: its top is the robot's height
  // A dark skirt over the wheels, the white body, and the dome on top.
  items.push_back(shape_item(Shape::Cylinder, frame, {0.0f, 0.0f, 0.025f}, {2.0f * r, 2.0f * r, 0.05f}, dark));
  items.push_back(shape_item(Shape::Cylinder, frame, {0.0f, 0.0f, (0.05f + head_z) / 2.0f},
                             {1.96f * r, 1.96f * r, head_z - 0.05f}, white));
  items.push_back(shape_item(Shape::Sphere, frame, {0.0f, 0.0f, head_z}, Eigen::Vector3f::Constant(1.9f * r), white));
  // A dark band where the head meets the body, and two eyes on the front: they show its heading.
  items.push_back(shape_item(Shape::Cylinder, frame, {0.0f, 0.0f, head_z}, {2.02f * r, 2.02f * r, 0.12f * r}, dark));
  const float eye_up = 0.4f * r;
  const float eye_out = std::sqrt(0.95f * 0.95f * r * r - eye_up * eye_up);
  for (const float side : {1.0f, -1.0f}) {
    const float a = 0.32f * side;
    items.push_back(shape_item(Shape::Sphere, frame, {eye_out * std::cos(a), eye_out * std::sin(a), head_z + eye_up},
                               Eigen::Vector3f::Constant(0.24f * r), dark));
  }
  append_soft_shadow(items, x, y, 1.25f * r);
}

}  // namespace rfbsim::sim
