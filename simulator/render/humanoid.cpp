// SPDX-License-Identifier: GPL-2.0-or-later
// Humanoids: the avatar's and the pedestrians' walking figures, each person with a look of its own.
#include <algorithm>
#include <array>
#include <cmath>

#include "render/scene_builder.hpp"
#include "render/scene_parts.hpp"
#include "render/shape_items.hpp"

namespace rfbsim::sim {

namespace {

// A limb's frame: hanging from `pivot` (body frame) and swung by `angle` about the body's y axis.
Eigen::Affine3f limb_frame(const Eigen::Affine3f& body, const Eigen::Vector3f& pivot, float angle) {
  return body * Eigen::Translation3f(pivot) * Eigen::AngleAxisf(angle, Eigen::Vector3f::UnitY());
}

// Palettes the pedestrians' looks are drawn from; everyday clothes and a range of skin and hair.
constexpr std::array<std::uint32_t, 6> kTrousers{0x2b3a55, 0x1f1f24, 0x8a7a5c, 0x55585e, 0x4a3a2e, 0x3d4a38};
constexpr std::array<std::uint32_t, 5> kSkin{0xf1c7a8, 0xe0ac8a, 0xc68d6a, 0x9c6a4a, 0x6e4630};
constexpr std::array<std::uint32_t, 6> kHair{0x1a1410, 0x3b2a1e, 0x6b4a2e, 0xb08a5a, 0x8a8a88, 0x2a2624};
constexpr std::array<std::uint32_t, 3> kShoes{0x202020, 0x5a3a24, 0xd0d0cc};

template <std::size_t N>
Eigen::Vector3f pick(const std::array<std::uint32_t, N>& palette, std::uint32_t hash) {
  return rgb(palette[hash % N]);
}

}  // namespace

HumanoidLook humanoid_look(int id, const Eigen::Vector3f& shirt) {
  // Each trait takes its own byte of the id's hash, so that traits vary independently across a crowd.
  const std::uint32_t h = mix_hash(static_cast<std::uint32_t>(id) + 0x51ed270bU);
  HumanoidLook look;
  look.shirt = shirt;
  look.trousers = pick(kTrousers, h & 0xff);
  look.skin = pick(kSkin, (h >> 8) & 0xff);
  look.hair = pick(kHair, (h >> 16) & 0xff);
  look.shoes = pick(kShoes, (h >> 24) & 0x0f);
  look.build = 0.92f + 0.16f * static_cast<float>((h >> 28) & 0x0f) / 15.0f;
  return look;
}

void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const HumanoidLook& look) {
  const float s = height / 1.75f;  // proportions below are for a 1.75 m person
  const Eigen::Affine3f body = Eigen::Translation3f(position) * Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()) *
                               Eigen::Scaling(s, s * look.build, s);
  const float leg = 0.6f * swing * std::sin(gait_phase);
  const float bob = 0.03f * swing * std::abs(std::cos(gait_phase));

  // Legs swing from the hips, each with a shoe pointing forward at its foot.
  for (const float side : {1.0f, -1.0f}) {
    const Eigen::Affine3f hip = limb_frame(body, {0.0f, 0.1f * side, 0.9f + bob}, side * leg);
    items.push_back(box_item(hip, {0.0f, 0.0f, -0.44f}, {0.14f, 0.13f, 0.88f}, look.trousers));
    items.push_back(box_item(hip, {0.04f, 0.0f, -0.865f}, {0.25f, 0.12f, 0.07f}, look.shoes));
  }
  items.push_back(box_item(body, {0.0f, 0.0f, 1.2f + bob}, {0.24f, 0.42f, 0.62f}, look.shirt));
  // Arms swing against the legs, as in a natural walk; a hand at the end of each sleeve.
  for (const float side : {1.0f, -1.0f}) {
    const Eigen::Affine3f shoulder = limb_frame(body, {0.0f, 0.27f * side, 1.48f + bob}, -0.8f * side * leg);
    items.push_back(box_item(shoulder, {0.0f, 0.0f, -0.28f}, {0.1f, 0.1f, 0.56f}, look.shirt));
    items.push_back(shape_item(Shape::Sphere, shoulder, {0.0f, 0.0f, -0.6f}, {0.1f, 0.1f, 0.12f}, look.skin));
  }
  items.push_back(
      shape_item(Shape::Sphere, body, {0.0f, 0.0f, 1.63f + bob}, Eigen::Vector3f::Constant(0.24f), look.skin));
  // Hair caps the head a little to the back, so the face shows which way the person looks. Its crown is
  // 1 cm above the head's, or the faceted head would poke through it.
  items.push_back(shape_item(Shape::Sphere, body, {-0.015f, 0.0f, 1.68f + bob}, {0.256f, 0.256f, 0.16f}, look.hair));
  // A nose-like marker shows which way the person faces, even from behind and above.
  items.push_back(box_item(body, {0.12f, 0.0f, 1.62f + bob}, {0.06f, 0.05f, 0.05f}, look.skin * 0.8f));
}

void append_humanoid(std::vector<DrawItem>& items, const Eigen::Vector3f& position, float yaw, float gait_phase,
                     float swing, float height, const Eigen::Vector3f& shirt) {
  HumanoidLook look;
  look.shirt = shirt;
  append_humanoid(items, position, yaw, gait_phase, swing, height, look);
}

void append_person(std::vector<DrawItem>& items, const Person& person) {
  const auto x = static_cast<float>(person.pose.x);
  const auto y = static_cast<float>(person.pose.y);
  const auto height = static_cast<float>(person.height);
  // The stride matches the speed: full swing at a brisk 1.3 m/s, none standing still.
  const float swing = std::min(1.0f, static_cast<float>(person.velocity.norm()) / 1.3f);
  append_humanoid(items, {x, y, 0.0f}, static_cast<float>(person.pose.yaw), static_cast<float>(person.gait_phase),
                  swing, height, humanoid_look(person.id, rgb(person.rgb)));
  append_soft_shadow(items, x, y, 0.4f * height / 1.75f);
}

}  // namespace rfbsim::sim
