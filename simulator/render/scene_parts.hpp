// SPDX-License-Identifier: GPL-2.0-or-later
// The scene builder's parts: each appends the draw items of one kind of thing in the world. Plain data
// only (no GL); build_scene calls them, and tests call them one at a time.
#pragma once

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

/// The robot's stand-in: a white rounded body of its radius and height with a dark band and two eyes
/// on the front (its heading), and a soft shadow.
void append_robot(std::vector<DrawItem>& items, const Robot& robot);

}  // namespace rfbsim::sim
