// SPDX-License-Identifier: GPL-2.0-or-later
// GlRenderer: one shader, four unit meshes, one draw call per item with only changed state set.
#include "render/gl_renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace rfbsim::sim {

namespace {

// Lighting: a hemisphere ambient (sky above, floor bounce below) plus one sun, and distance fog.
// Both make depth read on a flat screen: surfaces facing away are darker, far things fade into the sky.
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
uniform mat4 u_model;
uniform mat4 u_view_projection;
uniform mat3 u_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
void main() {
  vec4 world = u_model * vec4(in_position, 1.0);
  v_world = world.xyz;
  v_normal = normalize(u_normal_matrix * in_normal);
  gl_Position = u_view_projection * world;
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_world;
in vec3 v_normal;
uniform vec3 u_color;
uniform float u_opacity;
uniform int u_surface;      // 0 plain, 1 floor, 2 wall
uniform vec3 u_sun;         // direction the light travels, normalised
uniform vec3 u_sky;
uniform vec3 u_eye;
uniform vec2 u_fog;         // start, end (m)
out vec4 out_color;
void main() {
  vec3 n = normalize(v_normal);
  vec3 base = u_color;
  if (u_surface == 1) {
    // 1 m tiles with thin grout lines.
    vec2 cell = fract(v_world.xy);
    float grout = step(0.97, max(cell.x, cell.y));
    float checker = mod(floor(v_world.x) + floor(v_world.y), 2.0);
    base *= mix(1.0, 0.9, checker) * mix(1.0, 0.7, grout);
  } else if (u_surface == 2) {
    base *= mix(0.7, 1.0, smoothstep(0.0, 0.8, v_world.z));
  }
  float hemi = 0.5 + 0.5 * n.z;
  vec3 ambient = mix(vec3(0.36, 0.34, 0.32), vec3(0.55, 0.58, 0.64), hemi);
  float sun = max(dot(n, -u_sun), 0.0);
  vec3 lit = base * (ambient + 0.75 * sun * vec3(1.0, 0.97, 0.9));
  float fog = smoothstep(u_fog.x, u_fog.y, distance(v_world, u_eye));
  out_color = vec4(mix(lit, u_sky, fog), u_opacity);
}
)";

struct Mesh {
  GLuint vao = 0;
  GLuint vbo = 0;
  GLsizei vertices = 0;
};

using Vertex = std::array<float, 6>;  // position xyz, normal xyz

void add_triangle(std::vector<Vertex>& out, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                  const Eigen::Vector3f& c, const Eigen::Vector3f& na, const Eigen::Vector3f& nb,
                  const Eigen::Vector3f& nc) {
  out.push_back({a.x(), a.y(), a.z(), na.x(), na.y(), na.z()});
  out.push_back({b.x(), b.y(), b.z(), nb.x(), nb.y(), nb.z()});
  out.push_back({c.x(), c.y(), c.z(), nc.x(), nc.y(), nc.z()});
}

std::vector<Vertex> box_vertices() {
  std::vector<Vertex> v;
  // Each face: normal axis, and two in-plane axes ordered so that triangles wind counter-clockwise.
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {-1.0f, 1.0f}) {
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

std::vector<Vertex> sphere_vertices(int slices, int stacks) {
  std::vector<Vertex> v;
  const auto point = [&](int slice, int stack) {
    const float theta = static_cast<float>(stack) / static_cast<float>(stacks) * std::numbers::pi_v<float>;
    const float phi = static_cast<float>(slice) / static_cast<float>(slices) * 2.0f * std::numbers::pi_v<float>;
    return Eigen::Vector3f(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  for (int stack = 0; stack < stacks; ++stack) {
    for (int slice = 0; slice < slices; ++slice) {
      const auto a = point(slice, stack), b = point(slice, stack + 1);
      const auto c = point(slice + 1, stack + 1), d = point(slice + 1, stack);
      add_triangle(v, a * 0.5f, b * 0.5f, c * 0.5f, a, b, c);
      add_triangle(v, a * 0.5f, c * 0.5f, d * 0.5f, a, c, d);
    }
  }
  return v;
}

std::vector<Vertex> cylinder_vertices(int slices) {
  std::vector<Vertex> v;
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  for (int i = 0; i < slices; ++i) {
    const float a0 = static_cast<float>(i) / static_cast<float>(slices) * 2.0f * std::numbers::pi_v<float>;
    const float a1 = static_cast<float>(i + 1) / static_cast<float>(slices) * 2.0f * std::numbers::pi_v<float>;
    const Eigen::Vector3f n0{std::cos(a0), std::sin(a0), 0.0f}, n1{std::cos(a1), std::sin(a1), 0.0f};
    const Eigen::Vector3f b0 = n0 * 0.5f - up * 0.5f, b1 = n1 * 0.5f - up * 0.5f;
    const Eigen::Vector3f t0 = n0 * 0.5f + up * 0.5f, t1 = n1 * 0.5f + up * 0.5f;
    add_triangle(v, b0, b1, t1, n0, n1, n1);
    add_triangle(v, b0, t1, t0, n0, n1, n0);
    add_triangle(v, up * 0.5f, t0, t1, up, up, up);
    add_triangle(v, -up * 0.5f, b1, b0, -up, -up, -up);
  }
  return v;
}

std::vector<Vertex> disc_vertices(int slices) {
  std::vector<Vertex> v;
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  for (int i = 0; i < slices; ++i) {
    const float a0 = static_cast<float>(i) / static_cast<float>(slices) * 2.0f * std::numbers::pi_v<float>;
    const float a1 = static_cast<float>(i + 1) / static_cast<float>(slices) * 2.0f * std::numbers::pi_v<float>;
    add_triangle(v, Eigen::Vector3f::Zero(), {0.5f * std::cos(a0), 0.5f * std::sin(a0), 0.0f},
                 {0.5f * std::cos(a1), 0.5f * std::sin(a1), 0.0f}, up, up, up);
  }
  return v;
}

Mesh upload(const std::vector<Vertex>& vertices) {
  Mesh mesh;
  mesh.vertices = static_cast<GLsizei>(vertices.size());
  glGenVertexArrays(1, &mesh.vao);
  glGenBuffers(1, &mesh.vbo);
  glBindVertexArray(mesh.vao);
  glBindBuffer(GL_ARRAY_BUFFER, mesh.vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
  return mesh;
}

GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == 0) {
    std::string log(4096, '\0');
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error("shader compile failed: " + std::string(log.c_str()));
  }
  return shader;
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
  GLint u_model = -1, u_view_projection = -1, u_normal_matrix = -1, u_color = -1, u_opacity = -1;
  GLint u_surface = -1, u_sun = -1, u_sky = -1, u_eye = -1, u_fog = -1;
};

GlRenderer::GlRenderer() : impl_(std::make_unique<Impl>()) {
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  impl_->program = glCreateProgram();
  glAttachShader(impl_->program, vs);
  glAttachShader(impl_->program, fs);
  glLinkProgram(impl_->program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(impl_->program, GL_LINK_STATUS, &ok);
  if (ok == 0) throw std::runtime_error("shader link failed");
  const auto uniform = [&](const char* name) { return glGetUniformLocation(impl_->program, name); };
  impl_->u_model = uniform("u_model");
  impl_->u_view_projection = uniform("u_view_projection");
  impl_->u_normal_matrix = uniform("u_normal_matrix");
  impl_->u_color = uniform("u_color");
  impl_->u_opacity = uniform("u_opacity");
  impl_->u_surface = uniform("u_surface");
  impl_->u_sun = uniform("u_sun");
  impl_->u_sky = uniform("u_sky");
  impl_->u_eye = uniform("u_eye");
  impl_->u_fog = uniform("u_fog");
  impl_->meshes[static_cast<int>(Shape::Box)] = upload(box_vertices());
  impl_->meshes[static_cast<int>(Shape::Sphere)] = upload(sphere_vertices(20, 12));
  impl_->meshes[static_cast<int>(Shape::Cylinder)] = upload(cylinder_vertices(24));
  impl_->meshes[static_cast<int>(Shape::Disc)] = upload(disc_vertices(24));
}

GlRenderer::~GlRenderer() {
  for (auto& mesh : impl_->meshes) {
    glDeleteBuffers(1, &mesh.vbo);
    glDeleteVertexArrays(1, &mesh.vao);
  }
  glDeleteProgram(impl_->program);
}

void GlRenderer::draw(const Scene& scene, int width, int height) {
  glViewport(0, 0, width, height);
  glClearColor(scene.sky.x(), scene.sky.y(), scene.sky.z(), 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
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

  // Per item only the model and normal matrices change as a rule; the mesh, colour, opacity and surface are
  // set only when they differ from the previous item's (a scene of a few thousand items repeats them a lot).
  std::uint64_t triangles = 0;
  const Mesh* bound = nullptr;
  Eigen::Vector3f last_color = Eigen::Vector3f::Constant(-1.0f);
  float last_opacity = -1.0f;
  int last_surface = -1;
  const auto draw_item = [&](const DrawItem& item) {
    const Eigen::Matrix4f model = item.model.matrix();
    const Eigen::Matrix3f normal_matrix = item.model.linear().inverse().transpose();
    glUniformMatrix4fv(impl_->u_model, 1, GL_FALSE, model.data());
    glUniformMatrix3fv(impl_->u_normal_matrix, 1, GL_FALSE, normal_matrix.data());
    if (item.color != last_color) {
      glUniform3fv(impl_->u_color, 1, item.color.data());
      last_color = item.color;
    }
    if (item.opacity != last_opacity) {
      glUniform1f(impl_->u_opacity, item.opacity);
      last_opacity = item.opacity;
    }
    if (static_cast<int>(item.surface) != last_surface) {
      last_surface = static_cast<int>(item.surface);
      glUniform1i(impl_->u_surface, last_surface);
    }
    const Mesh& mesh = impl_->meshes[static_cast<std::size_t>(item.shape)];
    if (&mesh != bound) {
      glBindVertexArray(mesh.vao);
      bound = &mesh;
    }
    glDrawArrays(GL_TRIANGLES, 0, mesh.vertices);
    triangles += static_cast<std::uint64_t>(mesh.vertices / 3);
  };
  // Opaque items first, one shape at a time (the depth test makes their order free), so each mesh is
  // bound once; translucent ones (shadows) then blend over them in scene order without writing depth.
  for (std::size_t shape = 0; shape < impl_->meshes.size(); ++shape) {
    for (const DrawItem& item : scene.items) {
      if (item.opacity >= 1.0f && static_cast<std::size_t>(item.shape) == shape) draw_item(item);
    }
  }
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  for (const DrawItem& item : scene.items) {
    if (item.opacity < 1.0f) draw_item(item);
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glBindVertexArray(0);
  last_triangles_ = triangles;
}

}  // namespace rfbsim::sim
