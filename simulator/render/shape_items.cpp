// SPDX-License-Identifier: GPL-2.0-or-later
// Shared scene-builder helpers: colours, placed unit shapes, soft shadows and deterministic hashes.
#include "render/shape_items.hpp"

#include <cmath>
#include <tuple>

namespace rfbsim::sim {

Eigen::Vector3f rgb(std::uint32_t hex) {
  return {static_cast<float>((hex >> 16) & 0xff) / 255.0f, static_cast<float>((hex >> 8) & 0xff) / 255.0f,
          static_cast<float>(hex & 0xff) / 255.0f};
}

DrawItem shape_item(Shape shape, const Eigen::Affine3f& frame, const Eigen::Vector3f& centre,
                    const Eigen::Vector3f& size, const Eigen::Vector3f& color) {
  DrawItem item;
  item.shape = shape;
  item.model = frame * Eigen::Translation3f(centre) * Eigen::Scaling(size);
  item.color = color;
  return item;
}

void append_soft_shadow(std::vector<DrawItem>& items, float x, float y, float radius) {
  // Two translucent discs blend into a darker core with a fading rim: cheaper than a blurred texture.
  for (const auto& [scale, opacity, lift] : {std::tuple{1.0f, 0.16f, 0.008f}, std::tuple{0.6f, 0.22f, 0.01f}}) {
    DrawItem disc;
    disc.shape = Shape::Disc;
    disc.model = Eigen::Translation3f(x, y, lift) * Eigen::Scaling(2.0f * radius * scale);
    disc.color = {0.0f, 0.0f, 0.0f};
    disc.opacity = opacity;
    items.push_back(disc);
  }
}

std::uint32_t mix_hash(std::uint32_t value) {
  // The "lowbias32" integer finaliser: every input bit affects every output bit.
  value ^= value >> 16;
  value *= 0x7feb352dU;
  value ^= value >> 15;
  value *= 0x846ca68bU;
  value ^= value >> 16;
  return value;
}

std::uint32_t position_hash(double x, double y) {
  const auto cx = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(x * 100.0)));
  const auto cy = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(y * 100.0)));
  return mix_hash(cx ^ mix_hash(cy + 0x9e3779b9U));
}

}  // namespace rfbsim::sim
