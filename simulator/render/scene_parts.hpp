// SPDX-License-Identifier: GPL-2.0-or-later
// The scene builder's parts: each appends the draw items of one kind of thing in the world. Plain data
// only (no GL); build_scene calls them, and tests call them one at a time.
#pragma once

#include <cstddef>
#include <vector>

#include "render/draw_list.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// A pedestrian: a humanoid in its shirt colour and height, walking with its gait phase (the stride
/// grows with its speed), trousers, skin and hair picked from its id, and a soft shadow.
void append_person(std::vector<DrawItem>& items, const Person& person);

/// A prop by kind, turned by its yaw, inside its box (footprint and height): a crate with a lid and a
/// band; pallet racking with goods on its boards; a desk with a monitor and a keyboard.
void append_prop(std::vector<DrawItem>& items, const Prop& prop);

/// A landmark: a ring on the floor and a tall pole with a ball, both in its colour, seen from afar.
void append_landmark(std::vector<DrawItem>& items, const Landmark& landmark);

/// The robot as a Kuri-like figure of its radius and height (m): a cream body tapering from a dark skirt,
/// a dark sensor window and a heart light on its front (the body's heading; the light's colour tells the
/// navigator's state), a dome head turned by head_yaw with a dark face and two eyes, and a soft shadow.
/// Items come in that order: kRobotBodyItems of the body (skirt, body, shoulders, window, light), then
/// kRobotHeadItems of the head (dome, face, eye, glint, eye, glint), then the shadow's two. A pose that is
/// not finite, or a size that is not positive, draws nothing.
void append_robot(std::vector<DrawItem>& items, const Robot& robot);
inline constexpr std::size_t kRobotBodyItems = 5;  ///< append_robot's first items, fixed to the body
inline constexpr std::size_t kRobotHeadItems = 6;  ///< the items after them, turned with the head

}  // namespace rfbsim::sim
