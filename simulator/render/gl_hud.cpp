// SPDX-License-Identifier: GPL-2.0-or-later
// GlHudLayer: one textured quad per HUD image, its corners computed from gl_VertexID (no vertex buffer),
// its texels fetched by integer pixel position so that nothing is filtered or scaled.
#include "render/gl_hud.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstddef>
#include <stdexcept>
#include <string>

#include "render/gl_program.hpp"

namespace rfbsim::sim {

namespace {

// u_rect: the image's left, top, width and height in frame pixels (y down). The quad covers exactly those
// pixels, so each one's fragment is shaded once.
constexpr const char* kHudVertexShader = R"(#version 330 core
uniform vec4 u_rect;
uniform vec2 u_frame;
void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));  // strip: (0,0) (1,0) (0,1) (1,1)
  vec2 pixel = u_rect.xy + corner * u_rect.zw;
  gl_Position = vec4(pixel.x / u_frame.x * 2.0 - 1.0, 1.0 - pixel.y / u_frame.y * 2.0, 0.0, 1.0);
}
)";

// GL counts rows up from the bottom; the images count them down from the top (texture row 0 = top row).
constexpr const char* kHudFragmentShader = R"(#version 330 core
uniform sampler2D u_image;
uniform vec4 u_rect;
uniform vec2 u_frame;
out vec4 out_color;
void main() {
  ivec2 frame_pixel = ivec2(int(gl_FragCoord.x), int(u_frame.y) - 1 - int(gl_FragCoord.y));
  ivec2 texel = frame_pixel - ivec2(u_rect.xy);
  out_color = texelFetch(u_image, clamp(texel, ivec2(0), ivec2(u_rect.zw) - 1), 0);
}
)";


// The state draw() changes, read before and put back after, so that the layer can sit between any two
// draws. Queries are cheap on a software rasterizer and cost a sync at most once a frame on a GPU.
struct SavedState {
  GLboolean blend = GL_FALSE, depth_test = GL_FALSE, cull_face = GL_FALSE, scissor_test = GL_FALSE;
  GLboolean depth_mask = GL_TRUE;
  GLint blend_src_rgb = 0, blend_dst_rgb = 0, blend_src_alpha = 0, blend_dst_alpha = 0;
  GLint blend_equation_rgb = 0, blend_equation_alpha = 0;
  GLint program = 0, vertex_array = 0, active_texture = 0, texture = 0, unpack_alignment = 4;
  GLint viewport[4] = {0, 0, 0, 0};

  static SavedState read() {
    SavedState s;
    s.blend = glIsEnabled(GL_BLEND);
    s.depth_test = glIsEnabled(GL_DEPTH_TEST);
    s.cull_face = glIsEnabled(GL_CULL_FACE);
    s.scissor_test = glIsEnabled(GL_SCISSOR_TEST);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &s.depth_mask);
    glGetIntegerv(GL_BLEND_SRC_RGB, &s.blend_src_rgb);
    glGetIntegerv(GL_BLEND_DST_RGB, &s.blend_dst_rgb);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &s.blend_src_alpha);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &s.blend_dst_alpha);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &s.blend_equation_rgb);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &s.blend_equation_alpha);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s.program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s.vertex_array);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &s.active_texture);
    glActiveTexture(GL_TEXTURE0);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &s.texture);
    glGetIntegerv(GL_VIEWPORT, s.viewport);
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &s.unpack_alignment);
    return s;
  }

  void restore() const {
    const auto set = [](GLenum cap, GLboolean on) { on != GL_FALSE ? glEnable(cap) : glDisable(cap); };
    set(GL_BLEND, blend);
    set(GL_DEPTH_TEST, depth_test);
    set(GL_CULL_FACE, cull_face);
    set(GL_SCISSOR_TEST, scissor_test);
    glDepthMask(depth_mask);
    glBlendFuncSeparate(static_cast<GLenum>(blend_src_rgb), static_cast<GLenum>(blend_dst_rgb),
                        static_cast<GLenum>(blend_src_alpha), static_cast<GLenum>(blend_dst_alpha));
    glBlendEquationSeparate(static_cast<GLenum>(blend_equation_rgb), static_cast<GLenum>(blend_equation_alpha));
    glUseProgram(static_cast<GLuint>(program));
    glBindVertexArray(static_cast<GLuint>(vertex_array));
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(texture));  // on unit 0, still active
    glActiveTexture(static_cast<GLenum>(active_texture));
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    glPixelStorei(GL_UNPACK_ALIGNMENT, unpack_alignment);
  }
};

}  // namespace

struct GlHudLayer::Impl {
  GLuint program = 0;
  GLuint vertex_array = 0;  // empty: the vertex shader makes its corners, but core GL needs one bound
  GLint u_rect = -1, u_frame = -1, u_image = -1;
  // Slot i holds the texture of the i-th image drawn last, and a copy of that image to compare with.
  std::vector<GLuint> textures;
  std::vector<HudImage> uploaded;
};

GlHudLayer::GlHudLayer() : impl_(std::make_unique<Impl>()) {
  impl_->program = link_gl_program(kHudVertexShader, kHudFragmentShader, "HUD shader");
  impl_->u_rect = glGetUniformLocation(impl_->program, "u_rect");
  impl_->u_frame = glGetUniformLocation(impl_->program, "u_frame");
  impl_->u_image = glGetUniformLocation(impl_->program, "u_image");
  glGenVertexArrays(1, &impl_->vertex_array);
}

GlHudLayer::~GlHudLayer() {
  if (!impl_->textures.empty()) {
    glDeleteTextures(static_cast<GLsizei>(impl_->textures.size()), impl_->textures.data());
  }
  glDeleteVertexArrays(1, &impl_->vertex_array);
  glDeleteProgram(impl_->program);
}

void GlHudLayer::draw(const std::vector<PlacedHudImage>& images, int frame_width, int frame_height) {
  if (images.empty() || frame_width <= 0 || frame_height <= 0) return;
  const SavedState saved = SavedState::read();

  glViewport(0, 0, frame_width, frame_height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glDepthMask(GL_FALSE);
  // Straight alpha over the frame; the frame's alpha stays 1 (a + 1 * (1 - a)).
  glEnable(GL_BLEND);
  glBlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(impl_->program);
  glBindVertexArray(impl_->vertex_array);
  glUniform1i(impl_->u_image, 0);
  glUniform2f(impl_->u_frame, static_cast<float>(frame_width), static_cast<float>(frame_height));

  for (std::size_t i = 0; i < images.size(); ++i) {
    const HudImage& image = images[i].image;
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4) {
      continue;  // nothing to draw, or not a whole picture
    }
    // Upload into slot i only when its image changed: the HUD changes about once a second, frames come 30 times.
    while (impl_->textures.size() <= i) {
      GLuint texture = 0;
      glGenTextures(1, &texture);
      glBindTexture(GL_TEXTURE_2D, texture);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
      impl_->textures.push_back(texture);
      impl_->uploaded.emplace_back();
    }
    glBindTexture(GL_TEXTURE_2D, impl_->textures[i]);
    HudImage& last = impl_->uploaded[i];
    if (!(last == image)) {
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // RGBA8 rows are whole words; someone may have set 8
      if (last.width == image.width && last.height == image.height) {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                        image.rgba.data());
      } else {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                     image.rgba.data());
      }
      last = image;
      ++uploads_;
    }
    glUniform4f(impl_->u_rect, static_cast<float>(images[i].x), static_cast<float>(images[i].y),
                static_cast<float>(image.width), static_cast<float>(image.height));
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }

  saved.restore();
}

}  // namespace rfbsim::sim
