// SPDX-License-Identifier: GPL-2.0-or-later
// Props by kind: crates, warehouse pallet racking with goods, and desks with monitors. Every item stays
// inside the prop's turned box, since that box is what blocks walking and the map.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "render/scene_parts.hpp"
#include "render/shape_items.hpp"

namespace rfbsim::sim {

namespace {

// The prop's frame with local x along its longer side: racking and desks are built along their length
// whichever way the scenario gave the sizes. Returns the frame and the long and short extents.
struct LongFrame {
  Eigen::Affine3f frame;
  float length = 0.0f;
  float depth = 0.0f;
};

LongFrame long_frame(const Prop& prop) {
  LongFrame out;
  const bool along_y = prop.size_y > prop.size_x;
  const float turn = static_cast<float>(prop.yaw) + (along_y ? std::numbers::pi_v<float> / 2.0f : 0.0f);
  out.frame = Eigen::Translation3f(static_cast<float>(prop.x), static_cast<float>(prop.y), 0.0f) *
              Eigen::AngleAxisf(turn, Eigen::Vector3f::UnitZ());
  out.length = static_cast<float>(along_y ? prop.size_y : prop.size_x);
  out.depth = static_cast<float>(along_y ? prop.size_x : prop.size_y);
  return out;
}

// A fraction in [lo, hi] from 8 bits of a hash.
float spread(std::uint32_t hash, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(hash & 0xff) / 255.0f;
}

void append_crate(std::vector<DrawItem>& items, const Prop& prop) {
  const LongFrame f = long_frame(prop);
  const auto h = static_cast<float>(prop.height);
  const Eigen::Vector3f c = rgb(prop.rgb);
  // The body is inset a little so that the lid and the band stand proud of it and read as edges.
  items.push_back(
      box_item(f.frame, {0.0f, 0.0f, (h - 0.03f) / 2.0f}, {f.length - 0.02f, f.depth - 0.02f, h - 0.03f}, c));
  items.push_back(box_item(f.frame, {0.0f, 0.0f, h - 0.02f}, {f.length, f.depth, 0.04f}, c * 0.72f));
  items.push_back(
      box_item(f.frame, {0.0f, 0.0f, 0.45f * h}, {f.length, f.depth, std::min(0.08f, 0.15f * h)}, c * 0.6f));
}

// Racking colours: blue uprights and orange beams, as in most warehouses; galvanised decks.
const Eigen::Vector3f kUpright = rgb(0x1f4e9a);
const Eigen::Vector3f kBeam = rgb(0xe0701e);
const Eigen::Vector3f kDeck = rgb(0x8c9298);
// Goods: cardboard in a few shades, shrink-wrapped white, blue and red plastic totes, a green bale.
constexpr std::array<std::uint32_t, 8> kGoods{0xb08850, 0xc49a6c, 0x9a7444, 0xa8885e,
                                              0xd8d6cc, 0x3a6ea5, 0xb5483a, 0x5a8a4a};

void append_shelf(std::vector<DrawItem>& items, const Prop& prop) {
  const LongFrame f = long_frame(prop);
  const float L = f.length, D = f.depth;
  const auto h = static_cast<float>(prop.height);
  const float post = std::min(0.08f, 0.2f * D);  // upright section
  const float inset = 0.01f;                     // uprights stand just behind the beams' faces
  const float base = std::min(0.1f, 0.1f * h);   // the lowest deck, just off the floor
  const int levels = std::clamp(static_cast<int>(std::lround(h / 0.65f)), 2, 4);
  const float gap = (h - base) / static_cast<float>(levels);
  const int bays = std::max(1, static_cast<int>(std::lround((L - post) / 2.7f)));
  const float bay = (L - post) / static_cast<float>(bays);
  const float post_v = D / 2.0f - inset - post / 2.0f;

  // Uprights: a front and a back one at each bay end.
  for (int i = 0; i <= bays; ++i) {
    const float u = -L / 2.0f + post / 2.0f + static_cast<float>(i) * bay;
    for (const float side : {1.0f, -1.0f}) {
      items.push_back(box_item(f.frame, {u, side * post_v, h / 2.0f}, {post, post, h}, kUpright));
    }
  }
  // End frames: zig-zag bracing between the two uprights, one diagonal per level.
  const float brace_v = D - 2.0f * (post + inset);
  const float brace_z = 0.9f * gap;
  const float brace_len = std::hypot(brace_v, brace_z);
  const float brace_tilt = std::atan2(brace_v, brace_z);
  for (const float end : {1.0f, -1.0f}) {
    for (int k = 0; k < levels; ++k) {
      const float tilt = (k % 2 == 0 ? 1.0f : -1.0f) * brace_tilt;
      const Eigen::Affine3f at =
          f.frame *
          Eigen::Translation3f(end * (L / 2.0f - post / 2.0f), 0.0f, base + (static_cast<float>(k) + 0.5f) * gap) *
          Eigen::AngleAxisf(tilt, Eigen::Vector3f::UnitX());
      items.push_back(box_item(at, Eigen::Vector3f::Zero(), {0.03f, 0.03f, brace_len}, kUpright * 0.85f));
    }
  }
  // Each level: a beam along the front and the back, a deck between them, goods on the deck.
  const float deck_t = 0.03f;
  const float beam_w = 0.05f, beam_h = std::min(0.1f, 0.5f * gap);
  const std::uint32_t seed = position_hash(prop.x, prop.y);
  for (int k = 0; k < levels; ++k) {
    const float z = base + static_cast<float>(k) * gap;  // top of this level's deck
    for (const float side : {1.0f, -1.0f}) {
      items.push_back(
          box_item(f.frame, {0.0f, side * (D / 2.0f - beam_w / 2.0f), z - beam_h / 2.0f}, {L, beam_w, beam_h}, kBeam));
    }
    items.push_back(
        box_item(f.frame, {0.0f, 0.0f, z - deck_t / 2.0f}, {L - 2.0f * post, D - 2.0f * beam_w, deck_t}, kDeck));
    // Goods: each bay holds pallet-sized slots of about 1.2 m; a slot is empty, holds one load, or two
    // smaller cartons stacked. Sizes and colours come from the prop's position, so every rack is stocked
    // differently yet the same each frame.
    for (int b = 0; b < bays; ++b) {
      const float inner = bay - post - 0.06f;
      const int slots = std::max(1, static_cast<int>(inner / 1.2f));
      const float slot_w = inner / static_cast<float>(slots);
      for (int i = 0; i < slots; ++i) {
        const std::uint32_t hash = mix_hash(seed + static_cast<std::uint32_t>((k * 31 + b) * 7 + i));
        if (hash % 7 == 0) continue;  // an empty slot now and then
        const float u =
            -L / 2.0f + post + 0.03f + static_cast<float>(b) * bay + (static_cast<float>(i) + 0.5f) * slot_w;
        const float width = slot_w * spread(hash >> 3, 0.7f, 0.92f);
        const float deep = (D - 2.0f * beam_w) * spread(hash >> 11, 0.75f, 0.98f);
        const float tall = (gap - deck_t) * spread(hash >> 19, 0.45f, 0.82f);
        const Eigen::Vector3f colour = rgb(kGoods[(hash >> 27) % kGoods.size()]);
        if ((hash >> 30) == 0) {
          // Two cartons, the upper one smaller and a shade lighter: the stack reads as boxes, not a block.
          const float lower = 0.55f * tall;
          items.push_back(box_item(f.frame, {u, 0.0f, z + lower / 2.0f}, {width, deep, lower}, colour * 0.9f));
          items.push_back(box_item(f.frame, {u, 0.0f, z + lower + (tall - lower) / 2.0f},
                                   {0.85f * width, 0.85f * deep, tall - lower}, colour));
        } else {
          items.push_back(box_item(f.frame, {u, 0.0f, z + tall / 2.0f}, {width, deep, tall}, colour));
        }
      }
    }
  }
}

// Desk colours: dark metal legs, a black monitor with a dark blue-black screen, a grey keyboard.
const Eigen::Vector3f kMetal = rgb(0x3a3c40);
const Eigen::Vector3f kCasing = rgb(0x222326);
const Eigen::Vector3f kScreen = rgb(0x142234);
const Eigen::Vector3f kKeys = rgb(0x4a4c52);

void append_desk(std::vector<DrawItem>& items, const Prop& prop) {
  const LongFrame f = long_frame(prop);
  const float L = f.length, D = f.depth;
  const auto h = static_cast<float>(prop.height);
  const Eigen::Vector3f c = rgb(prop.rgb);
  // A desk at the usual 0.75 m, lower if the prop is too short to hold a monitor above it.
  const float top = std::min(0.75f, 0.62f * h);
  const float top_t = 0.03f;
  const float leg = 0.05f;
  items.push_back(box_item(f.frame, {0.0f, 0.0f, top - top_t / 2.0f}, {L, D, top_t}, c));
  for (const float su : {1.0f, -1.0f}) {
    for (const float sv : {1.0f, -1.0f}) {
      items.push_back(box_item(f.frame, {su * (L / 2.0f - leg), sv * (D / 2.0f - leg), (top - top_t) / 2.0f},
                               {leg, leg, top - top_t}, kMetal));
    }
  }
  // A modesty panel at the back (+y) closes the desk toward the monitor's side.
  const float panel = 0.4f * top;
  items.push_back(
      box_item(f.frame, {0.0f, D / 2.0f - leg, top - top_t - panel / 2.0f}, {L - 3.0f * leg, 0.02f, panel}, c * 0.8f));
  const float above = h - top;
  if (above < 0.2f) return;  // no room for a monitor

  // The monitor stands at the back and faces -y, where the user sits; its screen's top is the prop's top.
  const float mv = std::max(0.0f, D / 2.0f - 0.16f);
  const float sw = std::min(0.6f, 0.45f * L);
  const float sh = std::min(0.36f, 0.6f * above);
  const float screen_z = h - sh / 2.0f;
  items.push_back(box_item(f.frame, {0.0f, mv, top + 0.0075f}, {0.22f, 0.16f, 0.015f}, kCasing));
  items.push_back(
      box_item(f.frame, {0.0f, mv + 0.01f, (top + screen_z) / 2.0f}, {0.04f, 0.03f, screen_z - top}, kCasing));
  items.push_back(box_item(f.frame, {0.0f, mv - 0.01f, screen_z}, {sw, 0.04f, sh}, kCasing));
  items.push_back(box_item(f.frame, {0.0f, mv - 0.031f, screen_z}, {sw - 0.03f, 0.004f, sh - 0.03f}, kScreen));
  // The keyboard and the mouse lie in front of it, within the desk's front edge.
  const float kv = std::max(-D / 2.0f + 0.1f, mv - 0.32f);
  const float kw = std::min(0.45f, 0.35f * L);
  items.push_back(box_item(f.frame, {0.0f, kv, top + 0.01f}, {kw, 0.15f, 0.02f}, kKeys));
  items.push_back(box_item(f.frame, {kw / 2.0f + 0.1f, kv, top + 0.015f}, {0.06f, 0.1f, 0.03f}, kKeys));
}

}  // namespace

void append_prop(std::vector<DrawItem>& items, const Prop& prop) {
  switch (prop.kind) {
    case PropKind::Box:
      append_crate(items, prop);
      break;
    case PropKind::Shelf:
      append_shelf(items, prop);
      break;
    case PropKind::Desk:
      append_desk(items, prop);
      break;
  }
}

}  // namespace rfbsim::sim
