// SPDX-License-Identifier: GPL-2.0-or-later
// Unit meshes: each shape is written as a plain triangle list, then indexed by merging equal vertices.
#include "render/unit_meshes.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace rfbsim::sim {

namespace {

// Tessellation: enough for a smooth silhouette at the sizes people and robots appear in a 720p frame.
constexpr int kSphereSlices = 16;
constexpr int kSphereStacks = 10;
constexpr int kRoundSlices = 24;  // cylinders and discs

// Appends one triangle as three unindexed vertices.
void add_triangle(std::vector<MeshVertex>& out, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                  const Eigen::Vector3f& c, const Eigen::Vector3f& na, const Eigen::Vector3f& nb,
                  const Eigen::Vector3f& nc) {
  out.push_back({a.x(), a.y(), a.z(), na.x(), na.y(), na.z()});
  out.push_back({b.x(), b.y(), b.z(), nb.x(), nb.y(), nb.z()});
  out.push_back({c.x(), c.y(), c.z(), nc.x(), nc.y(), nc.z()});
}

std::vector<MeshVertex> box_triangles() {
  std::vector<MeshVertex> v;
  // Each face: its normal axis and two in-plane axes, ordered so that the triangles wind counter-clockwise.
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = sign;
      Eigen::Vector3f u = Eigen::Vector3f::Zero();
      Eigen::Vector3f w = Eigen::Vector3f::Zero();
      u[(axis + 1) % 3] = 0.5f;
      w[(axis + 2) % 3] = 0.5f;
      if (sign < 0.0f) std::swap(u, w);
      const Eigen::Vector3f c = n * 0.5f;
      add_triangle(v, c - u - w, c + u - w, c + u + w, n, n, n);
      add_triangle(v, c - u - w, c + u + w, c - u + w, n, n, n);
    }
  }
  return v;
}

std::vector<MeshVertex> sphere_triangles() {
  std::vector<MeshVertex> v;
  const auto point = [](int slice, int stack) {
    // At the poles every slice gives the same point, so that merging vertices closes the caps.
    if (stack == 0) return Eigen::Vector3f(0.0f, 0.0f, 1.0f);
    if (stack == kSphereStacks) return Eigen::Vector3f(0.0f, 0.0f, -1.0f);
    const float theta = static_cast<float>(stack) / kSphereStacks * std::numbers::pi_v<float>;
    const float phi = static_cast<float>(slice % kSphereSlices) / kSphereSlices * 2.0f * std::numbers::pi_v<float>;
    return Eigen::Vector3f(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  for (int stack = 0; stack < kSphereStacks; ++stack) {
    for (int slice = 0; slice < kSphereSlices; ++slice) {
      const auto a = point(slice, stack), b = point(slice, stack + 1);
      const auto c = point(slice + 1, stack + 1), d = point(slice + 1, stack);
      // The triangle that would collapse at a pole is left out.
      if (stack + 1 < kSphereStacks) add_triangle(v, a * 0.5f, b * 0.5f, c * 0.5f, a, b, c);
      if (stack > 0) add_triangle(v, a * 0.5f, c * 0.5f, d * 0.5f, a, c, d);
    }
  }
  return v;
}

Eigen::Vector3f rim(int i) {
  const float a = static_cast<float>(i % kRoundSlices) / kRoundSlices * 2.0f * std::numbers::pi_v<float>;
  return {std::cos(a), std::sin(a), 0.0f};
}

std::vector<MeshVertex> cylinder_triangles() {
  std::vector<MeshVertex> v;
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  for (int i = 0; i < kRoundSlices; ++i) {
    const Eigen::Vector3f n0 = rim(i), n1 = rim(i + 1);
    const Eigen::Vector3f b0 = n0 * 0.5f - up * 0.5f, b1 = n1 * 0.5f - up * 0.5f;
    const Eigen::Vector3f t0 = n0 * 0.5f + up * 0.5f, t1 = n1 * 0.5f + up * 0.5f;
    add_triangle(v, b0, b1, t1, n0, n1, n1);
    add_triangle(v, b0, t1, t0, n0, n1, n0);
    add_triangle(v, up * 0.5f, t0, t1, up, up, up);
    add_triangle(v, -up * 0.5f, b1, b0, -up, -up, -up);
  }
  return v;
}

std::vector<MeshVertex> disc_triangles() {
  std::vector<MeshVertex> v;
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  for (int i = 0; i < kRoundSlices; ++i) {
    add_triangle(v, Eigen::Vector3f::Zero(), rim(i) * 0.5f, rim(i + 1) * 0.5f, up, up, up);
  }
  return v;
}

// Merges bit-equal vertices (same position and normal): a smooth surface shares its vertices, a sharp
// edge keeps one per face because the normals differ.
UnitMesh indexed(const std::vector<MeshVertex>& triangles) {
  UnitMesh mesh;
  std::map<MeshVertex, std::uint16_t> seen;
  mesh.indices.reserve(triangles.size());
  for (const MeshVertex& vertex : triangles) {
    const auto [at, inserted] = seen.try_emplace(vertex, static_cast<std::uint16_t>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(vertex);
    mesh.indices.push_back(at->second);
  }
  if (mesh.vertices.size() > 0xffff) throw std::logic_error("unit mesh has too many vertices for 16-bit indices");
  return mesh;
}

}  // namespace

UnitMesh unit_mesh(Shape shape) {
  switch (shape) {
    case Shape::Box: return indexed(box_triangles());
    case Shape::Sphere: return indexed(sphere_triangles());
    case Shape::Cylinder: return indexed(cylinder_triangles());
    case Shape::Disc: return indexed(disc_triangles());
  }
  throw std::logic_error("unit_mesh: unknown shape");
}

}  // namespace rfbsim::sim
