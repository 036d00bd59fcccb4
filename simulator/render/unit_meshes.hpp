// SPDX-License-Identifier: GPL-2.0-or-later
// The unit shapes every draw item scales and places (draw_list.hpp's Shape), as indexed triangle meshes.
// Plain data, no GL: the renderer uploads them once; tests check their extents and normals.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "render/draw_list.hpp"

namespace rfbsim::sim {

/// One vertex: position xyz, then the outward unit normal xyz.
using MeshVertex = std::array<float, 6>;

/// An indexed triangle list, counter-clockwise seen from outside. Vertices shared by several triangles
/// appear once, so that a software rasterizer (llvmpipe) shades each of them once per instance.
struct UnitMesh {
  std::vector<MeshVertex> vertices;
  std::vector<std::uint16_t> indices;  ///< three per triangle
};

/// The mesh of `shape` at the size draw_list.hpp documents for it (a unit cube, a sphere and cylinder of
/// diameter 1, a disc of diameter 1).
UnitMesh unit_mesh(Shape shape);

}  // namespace rfbsim::sim
