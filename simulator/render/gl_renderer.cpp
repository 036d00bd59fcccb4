// SPDX-License-Identifier: GPL-2.0-or-later
// GlRenderer: one shader, four indexed unit meshes, and one instanced draw call per batch of items.
// Each item's placement, colour and surface travel as per-instance vertex attributes, so a scene of
// hundreds of items costs a handful of calls (a software rasterizer pays dearly for each call).
#include "render/gl_renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "render/draw_batches.hpp"
#include "render/gl_program.hpp"
#include "render/unit_meshes.hpp"

namespace rfbsim::sim {

namespace {

// Lighting: a hemisphere ambient (sky above, floor bounce below) plus one sun, and distance fog.
// Both make depth read on a flat screen: surfaces facing away are darker, far things fade into the sky.
constexpr const char* kSceneVertexShader = R"(#version 330 core
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
// Per instance (InstanceAttributes below).
layout(location = 2) in mat4 in_model;          // locations 2..5
layout(location = 6) in mat3 in_normal_matrix;  // locations 6..8
layout(location = 9) in vec4 in_color;          // rgb, opacity
layout(location = 10) in float in_surface;
uniform mat4 u_view_projection;
out vec3 v_world;
out vec3 v_normal;
flat out vec4 v_color;
flat out int v_surface;
void main() {
  vec4 world = in_model * vec4(in_position, 1.0);
  v_world = world.xyz;
  v_normal = normalize(in_normal_matrix * in_normal);
  v_color = in_color;
  v_surface = int(in_surface + 0.5);
  gl_Position = u_view_projection * world;
}
)";

constexpr const char* kSceneFragmentShader = R"(#version 330 core
in vec3 v_world;
in vec3 v_normal;
flat in vec4 v_color;
flat in int v_surface;      // 0 plain, 1 floor, 2 wall
uniform vec3 u_sun;         // direction the light travels, normalised
uniform vec3 u_sky;
uniform vec3 u_eye;
uniform vec2 u_fog;         // start, end (m)
out vec4 out_color;
void main() {
  vec3 n = normalize(v_normal);
  vec3 base = v_color.rgb;
  if (v_surface == 1) {
    // 1 m tiles with thin grout lines.
    vec2 cell = fract(v_world.xy);
    float grout = step(0.97, max(cell.x, cell.y));
    float checker = mod(floor(v_world.x) + floor(v_world.y), 2.0);
    base *= mix(1.0, 0.9, checker) * mix(1.0, 0.7, grout);
  } else if (v_surface == 2) {
    base *= mix(0.7, 1.0, smoothstep(0.0, 0.8, v_world.z));
  }
  float hemi = 0.5 + 0.5 * n.z;
  vec3 ambient = mix(vec3(0.36, 0.34, 0.32), vec3(0.55, 0.58, 0.64), hemi);
  float sun = max(dot(n, -u_sun), 0.0);
  vec3 lit = base * (ambient + 0.75 * sun * vec3(1.0, 0.97, 0.9));
  float fog = smoothstep(u_fog.x, u_fog.y, distance(v_world, u_eye));
  out_color = vec4(mix(lit, u_sky, fog), v_color.a);
}
)";

// One item's per-instance attributes, in the layout the vertex shader reads (all floats, tightly packed).
struct InstanceAttributes {
  std::array<float, 16> model;          // column-major 4x4
  std::array<float, 9> normal_matrix;   // column-major 3x3: inverse transpose of the model's linear part
  std::array<float, 4> color;           // rgb, opacity
  float surface;                        // Surface as a number
};
static_assert(sizeof(InstanceAttributes) == 30 * sizeof(float), "instance attributes must be tightly packed");
static_assert(std::is_standard_layout_v<InstanceAttributes>, "offsetof needs a standard-layout type");

constexpr GLuint kInstanceFirstLocation = 2;

InstanceAttributes instance_of(const DrawItem& item) {
  InstanceAttributes a{};
  const Eigen::Matrix4f model = item.model.matrix();
  const Eigen::Matrix3f normal_matrix = item.model.linear().inverse().transpose();
  std::copy(model.data(), model.data() + 16, a.model.begin());
  std::copy(normal_matrix.data(), normal_matrix.data() + 9, a.normal_matrix.begin());
  a.color = {item.color.x(), item.color.y(), item.color.z(), item.opacity};
  a.surface = static_cast<float>(static_cast<int>(item.surface));
  return a;
}

struct Mesh {
  GLuint vao = 0;
  GLuint vbo = 0;
  GLuint ibo = 0;
  GLsizei indices = 0;
};

Mesh upload(const UnitMesh& unit) {
  Mesh mesh;
  mesh.indices = static_cast<GLsizei>(unit.indices.size());
  glGenVertexArrays(1, &mesh.vao);
  glGenBuffers(1, &mesh.vbo);
  glGenBuffers(1, &mesh.ibo);
  glBindVertexArray(mesh.vao);
  glBindBuffer(GL_ARRAY_BUFFER, mesh.vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(unit.vertices.size() * sizeof(MeshVertex)),
               unit.vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(MeshVertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(MeshVertex), reinterpret_cast<void*>(3 * sizeof(float)));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.ibo);  // recorded in the VAO
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(unit.indices.size() * sizeof(std::uint16_t)),
               unit.indices.data(), GL_STATIC_DRAW);
  for (GLuint location = kInstanceFirstLocation; location < kInstanceFirstLocation + 9; ++location) {
    glEnableVertexAttribArray(location);
    glVertexAttribDivisor(location, 1);
  }
  glBindVertexArray(0);
  return mesh;
}

// Points the bound VAO's instance attributes at the instances from `first` on in the bound array buffer.
void point_instances_at(std::size_t first) {
  const auto at = [first](std::size_t offset_in_instance) {
    return reinterpret_cast<const void*>(first * sizeof(InstanceAttributes) + offset_in_instance);
  };
  constexpr auto stride = static_cast<GLsizei>(sizeof(InstanceAttributes));
  GLuint location = kInstanceFirstLocation;
  for (std::size_t column = 0; column < 4; ++column) {
    glVertexAttribPointer(location++, 4, GL_FLOAT, GL_FALSE, stride,
                          at(offsetof(InstanceAttributes, model) + column * 4 * sizeof(float)));
  }
  for (std::size_t column = 0; column < 3; ++column) {
    glVertexAttribPointer(location++, 3, GL_FLOAT, GL_FALSE, stride,
                          at(offsetof(InstanceAttributes, normal_matrix) + column * 3 * sizeof(float)));
  }
  glVertexAttribPointer(location++, 4, GL_FLOAT, GL_FALSE, stride, at(offsetof(InstanceAttributes, color)));
  glVertexAttribPointer(location, 1, GL_FLOAT, GL_FALSE, stride, at(offsetof(InstanceAttributes, surface)));
}


}  // namespace

Eigen::Matrix4f perspective(float fov_y_degrees, float aspect, float near_plane, float far_plane) {
  const float f = 1.0f / std::tan(fov_y_degrees * std::numbers::pi_v<float> / 360.0f);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  m(2, 3) = 2.0f * far_plane * near_plane / (near_plane - far_plane);
  m(3, 2) = -1.0f;
  return m;
}

Eigen::Matrix4f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up) {
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f side = forward.cross(up).normalized();
  const Eigen::Vector3f true_up = side.cross(forward);
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = side.transpose();
  m.block<1, 3>(1, 0) = true_up.transpose();
  m.block<1, 3>(2, 0) = -forward.transpose();
  m(0, 3) = -side.dot(eye);
  m(1, 3) = -true_up.dot(eye);
  m(2, 3) = forward.dot(eye);
  return m;
}

struct GlRenderer::Impl {
  GLuint program = 0;
  std::array<Mesh, 4> meshes{};  // indexed by Shape
  GLuint instance_buffer = 0;    // this frame's InstanceAttributes, in plan order
  std::vector<InstanceAttributes> instances;  // reused each frame
  GLint u_view_projection = -1, u_sun = -1, u_sky = -1, u_eye = -1, u_fog = -1;
};

GlRenderer::GlRenderer() : impl_(std::make_unique<Impl>()) {
  impl_->program = link_gl_program(kSceneVertexShader, kSceneFragmentShader, "shader");
  const auto uniform = [&](const char* name) { return glGetUniformLocation(impl_->program, name); };
  impl_->u_view_projection = uniform("u_view_projection");
  impl_->u_sun = uniform("u_sun");
  impl_->u_sky = uniform("u_sky");
  impl_->u_eye = uniform("u_eye");
  impl_->u_fog = uniform("u_fog");
  glGenBuffers(1, &impl_->instance_buffer);
  for (const Shape shape : {Shape::Box, Shape::Sphere, Shape::Cylinder, Shape::Disc}) {
    impl_->meshes[static_cast<std::size_t>(shape)] = upload(unit_mesh(shape));
  }
}

GlRenderer::~GlRenderer() {
  for (auto& mesh : impl_->meshes) {
    glDeleteBuffers(1, &mesh.vbo);
    glDeleteBuffers(1, &mesh.ibo);
    glDeleteVertexArrays(1, &mesh.vao);
  }
  glDeleteBuffers(1, &impl_->instance_buffer);
  glDeleteProgram(impl_->program);
}

void GlRenderer::draw(const Scene& scene, int width, int height) {
  glViewport(0, 0, width, height);
  glClearColor(scene.sky.x(), scene.sky.y(), scene.sky.z(), 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  // The state every batch starts from, whatever the context was left with.
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glUseProgram(impl_->program);

  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const Eigen::Matrix4f view_projection =
      perspective(scene.camera.fov_y_degrees, aspect, 0.05f, 200.0f) *
      look_at(scene.camera.eye, scene.camera.target, Eigen::Vector3f::UnitZ());
  glUniformMatrix4fv(impl_->u_view_projection, 1, GL_FALSE, view_projection.data());
  const Eigen::Vector3f sun = scene.sun_direction.normalized();
  glUniform3fv(impl_->u_sun, 1, sun.data());
  glUniform3fv(impl_->u_sky, 1, scene.sky.data());
  glUniform3fv(impl_->u_eye, 1, scene.camera.eye.data());
  glUniform2f(impl_->u_fog, scene.fog_start, scene.fog_end);

  // Every item's attributes in drawing order, uploaded at once into a fresh buffer (no wait on the last frame).
  const DrawPlan plan = plan_draws(scene);
  auto& instances = impl_->instances;
  instances.clear();
  for (const std::uint32_t index : plan.order) instances.push_back(instance_of(scene.items[index]));
  glBindBuffer(GL_ARRAY_BUFFER, impl_->instance_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(instances.size() * sizeof(InstanceAttributes)),
               instances.data(), GL_STREAM_DRAW);

  // One call per batch. Translucent batches (shadows) blend over the opaque picture without writing depth.
  std::uint64_t triangles = 0;
  for (const DrawBatch& batch : plan.batches) {
    if (batch.blended) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
    }
    const Mesh& mesh = impl_->meshes[static_cast<std::size_t>(batch.shape)];
    glBindVertexArray(mesh.vao);
    point_instances_at(batch.first);
    glDrawElementsInstanced(GL_TRIANGLES, mesh.indices, GL_UNSIGNED_SHORT, nullptr,
                            static_cast<GLsizei>(batch.count));
    triangles += static_cast<std::uint64_t>(mesh.indices / 3) * batch.count;
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glBindVertexArray(0);
  last_triangles_ = triangles;
  last_draw_calls_ = plan.batches.size();
}

}  // namespace rfbsim::sim
