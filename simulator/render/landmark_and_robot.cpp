// SPDX-License-Identifier: GPL-2.0-or-later
// Landmarks (a floor ring and a tall pole with a ball) and the robot (a Kuri-like body with a turning head).
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

namespace {

// The heart light's colour for each navigator state, so that a watcher (and a tester) can tell them apart.
Eigen::Vector3f heart_light(RobotState state) {
  switch (state) {
    case RobotState::Idle: return {0.85f, 0.9f, 1.0f};
    case RobotState::Planning: return {0.55f, 0.75f, 1.0f};
    case RobotState::Moving: return {0.35f, 0.95f, 0.8f};
    case RobotState::Recovering: return {1.0f, 0.7f, 0.2f};
    case RobotState::Arrived: return {0.45f, 1.0f, 0.4f};
    case RobotState::Failed: return {1.0f, 0.25f, 0.2f};
  }
  return {1.0f, 1.0f, 1.0f};
}

}  // namespace

void append_robot(std::vector<DrawItem>& items, const Robot& robot) {
  const bool drawable = std::isfinite(robot.pose.x) && std::isfinite(robot.pose.y) && std::isfinite(robot.pose.yaw) &&
                        robot.radius > 0.0 && robot.height > 0.0 && std::isfinite(robot.radius + robot.height);
  if (!drawable) return;
  const auto x = static_cast<float>(robot.pose.x);
  const auto y = static_cast<float>(robot.pose.y);
  const Eigen::Affine3f body = Eigen::Translation3f(x, y, 0.0f) *
                               Eigen::AngleAxisf(static_cast<float>(robot.pose.yaw), Eigen::Vector3f::UnitZ());
  // Widths follow the footprint radius, heights the robot's height (Kuri: 0.16 m and 0.5 m).
  const auto r = static_cast<float>(robot.radius);
  const float h = std::max(static_cast<float>(robot.height), 2.0f * r);
  const Eigen::Vector3f cream{0.95f, 0.94f, 0.9f};
  const Eigen::Vector3f dark{0.2f, 0.21f, 0.23f};

  // Body: a dark skirt over the wheels, a short cylinder, and a half-ellipsoid that tapers to the neck.
  const float waist = 0.28f * h;
  const float shoulder = 0.44f * h;  // the upper ellipsoid's half-height: it closes at 0.72 h, under the head
  items.push_back(shape_item(Shape::Cylinder, body, {0.0f, 0.0f, 0.04f * h}, {2.0f * r, 2.0f * r, 0.08f * h}, dark));
  items.push_back(shape_item(Shape::Cylinder, body, {0.0f, 0.0f, (0.07f * h + waist) / 2.0f},
                             {1.94f * r, 1.94f * r, waist - 0.07f * h}, cream));
  items.push_back(shape_item(Shape::Sphere, body, {0.0f, 0.0f, waist}, {1.94f * r, 1.94f * r, 2.0f * shoulder}, cream));
  // A dark window for the lidar and cliff sensors across the base's front, and the heart light on the chest,
  // in the navigator's state colour: both show which way the body faces, whatever the head does.
  items.push_back(shape_item(Shape::Sphere, body, {0.45f * r, 0.0f, 0.2f * h}, {1.1f * r, 1.4f * r, 0.1f * h}, dark));
  const float chest_z = 0.46f * h;
  const float chest_x = 0.97f * r * std::sqrt(1.0f - std::pow((chest_z - waist) / shoulder, 2.0f));
  items.push_back(shape_item(Shape::Sphere, body, {chest_x, 0.0f, chest_z}, {0.03f * h, 0.28f * r, 0.1f * h},
                             heart_light(robot.state)));

  // Head: a dome as wide as the shoulders, turned by head_yaw on the neck; its top is the robot's height.
  const float head_half = 0.16f * h;
  const float head_r = 0.72f * r;
  const float head_yaw = std::isfinite(robot.head_yaw) ? static_cast<float>(robot.head_yaw) : 0.0f;
  const Eigen::Affine3f head = body * Eigen::Translation3f(0.0f, 0.0f, h - head_half) *
                               Eigen::AngleAxisf(head_yaw, Eigen::Vector3f::UnitZ());
  items.push_back(shape_item(Shape::Sphere, head, Eigen::Vector3f::Zero(),
                             {2.0f * head_r, 2.0f * head_r, 2.0f * head_half}, cream));
  // The dark face: a flat ellipsoid that bulges out of the dome's front, a band from cheek to cheek.
  const float face_z = 0.02f * h;
  items.push_back(shape_item(Shape::Sphere, head, {0.58f * head_r, 0.0f, face_z},
                             {1.0f * head_r, 1.8f * head_r, 1.0f * head_half}, dark));
  // Two black eyes on the face, each with a glint, so that the head's turn reads from a few metres away.
  for (const float side : {1.0f, -1.0f}) {
    const Eigen::Vector3f eye{1.02f * head_r, side * 0.36f * head_r, face_z};
    items.push_back(shape_item(Shape::Sphere, head, eye, Eigen::Vector3f::Constant(0.38f * head_r),
                               {0.03f, 0.03f, 0.035f}));
    const Eigen::Vector3f glint = eye + head_r * Eigen::Vector3f{0.15f, 0.05f * side, 0.09f};  // forward, out, up
    items.push_back(
        shape_item(Shape::Sphere, head, glint, Eigen::Vector3f::Constant(0.1f * head_r), Eigen::Vector3f::Ones()));
  }
  append_soft_shadow(items, x, y, 1.25f * r);
}

}  // namespace rfbsim::sim
