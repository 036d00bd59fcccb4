// SPDX-License-Identifier: GPL-2.0-or-later
// Unit meshes: each shape fills exactly its documented extent, faces outward, and shares its vertices.
#include "render/unit_meshes.hpp"

#include <catch2/catch.hpp>
#include <cmath>

namespace {

using rfbsim::sim::MeshVertex;
using rfbsim::sim::Shape;
using rfbsim::sim::UnitMesh;

Eigen::Vector3f position(const MeshVertex& v) { return {v[0], v[1], v[2]}; }
Eigen::Vector3f normal(const MeshVertex& v) { return {v[3], v[4], v[5]}; }

// Every triangle's winding (counter-clockwise seen from outside) agrees with its vertices' normals.
void check_outward_and_indexed(const UnitMesh& mesh) {
  REQUIRE(mesh.indices.size() % 3 == 0);
  for (const std::uint16_t index : mesh.indices) REQUIRE(index < mesh.vertices.size());
  for (const MeshVertex& v : mesh.vertices) CHECK(normal(v).norm() == Approx(1.0f).margin(1e-5));
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    const MeshVertex& a = mesh.vertices[mesh.indices[i]];
    const MeshVertex& b = mesh.vertices[mesh.indices[i + 1]];
    const MeshVertex& c = mesh.vertices[mesh.indices[i + 2]];
    const Eigen::Vector3f face = (position(b) - position(a)).cross(position(c) - position(a));
    INFO("triangle " << i / 3);
    REQUIRE(face.norm() > 1e-6f);  // no degenerate triangles (the sphere's poles)
    CHECK(face.dot(normal(a) + normal(b) + normal(c)) > 0.0f);
  }
}

}  // namespace

TEST_CASE("the unit box spans -0.5..0.5 with a vertex per face corner") {
  const UnitMesh box = rfbsim::sim::unit_mesh(Shape::Box);
  check_outward_and_indexed(box);
  CHECK(box.vertices.size() == 24);  // 6 faces x 4 corners: sharp edges keep one normal per face
  CHECK(box.indices.size() == 36);
  for (const MeshVertex& v : box.vertices) CHECK(position(v).cwiseAbs().maxCoeff() == 0.5f);
}

TEST_CASE("the unit sphere has radius 0.5, normals along the radius, and shares its vertices") {
  const UnitMesh sphere = rfbsim::sim::unit_mesh(Shape::Sphere);
  check_outward_and_indexed(sphere);
  for (const MeshVertex& v : sphere.vertices) {
    CHECK(position(v).norm() == Approx(0.5f).margin(1e-5));
    CHECK((normal(v) - 2.0f * position(v)).norm() < 1e-5f);
  }
  // Indexed: each vertex serves several triangles (an unindexed list would have 3 per triangle).
  CHECK(sphere.vertices.size() * 5 < sphere.indices.size());
  CHECK(sphere.vertices.size() == 16 * 9 + 2);  // 16 slices x 9 inner rings, plus the two poles
}

TEST_CASE("the unit cylinder and disc have diameter 1 and the cylinder height 1") {
  const UnitMesh cylinder = rfbsim::sim::unit_mesh(Shape::Cylinder);
  check_outward_and_indexed(cylinder);
  float widest = 0.0f;
  for (const MeshVertex& v : cylinder.vertices) {
    widest = std::max(widest, std::hypot(v[0], v[1]));
    CHECK(std::abs(v[2]) <= 0.5f);
  }
  CHECK(widest == Approx(0.5f));
  const UnitMesh disc = rfbsim::sim::unit_mesh(Shape::Disc);
  check_outward_and_indexed(disc);
  for (const MeshVertex& v : disc.vertices) {
    CHECK(v[2] == 0.0f);
    CHECK(normal(v) == Eigen::Vector3f::UnitZ());
  }
  CHECK(disc.vertices.size() == 24 + 1);  // the rim and the centre
}
