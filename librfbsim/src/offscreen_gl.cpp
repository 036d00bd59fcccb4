// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::OffscreenGL: EGL without a window system, an OpenGL context (3.3 core or compatibility) and an FBO.
#include "rfbsim/offscreen_gl.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rfbsim {

namespace {

// The process-wide EGL display. EGL displays are shared per process: terminating one would pull it from
// under every other context, so it is opened once and never terminated.
struct SharedDisplay {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string platform;
};

std::string egl_error_text() {
  char text[32];
  std::snprintf(text, sizeof text, "EGL error 0x%04x", static_cast<unsigned>(eglGetError()));
  return text;
}

EGLDisplay try_device_platform(PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display) {
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  if (query_devices == nullptr) return EGL_NO_DISPLAY;
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (query_devices(16, devices, &count) != EGL_TRUE) return EGL_NO_DISPLAY;
  // The first device that initialises wins: a GPU where there is one, else Mesa's software device.
  for (EGLint i = 0; i < count; ++i) {
    EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr) == EGL_TRUE) return display;
  }
  return EGL_NO_DISPLAY;
}

SharedDisplay open_display(const std::string& platform) {
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    throw std::runtime_error("no EGL display: eglGetPlatformDisplayEXT is missing (is libEGL from GLVND installed?)");
  }
  SharedDisplay shared;
  if (platform == "auto" || platform == "device") {
    shared.display = try_device_platform(get_platform_display);
    shared.platform = "device";
  }
  if (shared.display == EGL_NO_DISPLAY && (platform == "auto" || platform == "surfaceless")) {
    EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr) == EGL_TRUE) {
      shared.display = display;
      shared.platform = "surfaceless";
    }
  }
  if (shared.display == EGL_NO_DISPLAY) {
    throw std::runtime_error("no EGL display for platform '" + platform +
                             "' (tried the device and Mesa surfaceless platforms; " + egl_error_text() + ")");
  }
  return shared;
}

const SharedDisplay& shared_display(const std::string& platform) {
  static std::mutex mutex;
  static SharedDisplay shared;
  std::lock_guard lock(mutex);
  if (shared.display == EGL_NO_DISPLAY) shared = open_display(platform);
  return shared;
}

void check_gl(const char* step) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    char text[96];
    std::snprintf(text, sizeof text, "OpenGL error 0x%04x during %s", error, step);
    throw std::runtime_error(text);
  }
}

// The MSAA samples to use, at most `most` (GL_MAX_SAMPLES). Automatic: 4 on a GPU; none on Mesa's software
// rasterizers, where 4x MSAA doubled the time of a 720p frame of the warehouse (bench_world) and the
// resolve alone took 6 ms.
int chosen_samples(int requested, const char* gl_renderer, int most) {
  int samples = requested;
  if (requested == OffscreenGLOptions::kAutoSamples) {
    const std::string name = gl_renderer != nullptr ? gl_renderer : "";
    const bool software = name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos;
    samples = software ? 0 : 4;
  }
  samples = std::min(samples, most);
  return samples > 1 ? samples : 0;
}

// The EGL attributes of a context of `profile`. Compatibility names no version: EGL then gives the newest
// compatibility context the driver has (Mesa llvmpipe: 4.5), which fixed-function renderers such as MuJoCo
// 2.x's need; asking for 3.3 compatibility would fail on drivers that stop compatibility at 3.0.
std::vector<EGLint> context_attributes(GLProfile profile) {
  if (profile == GLProfile::kCompatibility) {
    return {EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT, EGL_NONE};
  }
  return {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
          EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
}

const char* profile_name(GLProfile profile) {
  return profile == GLProfile::kCompatibility ? "compatibility" : "3.3 core";
}

// Width and height of colour attachment 0 of the framebuffer bound for reading, or {0, 0} when it has none.
// Restores the renderbuffer and texture bindings it touches.
std::pair<GLint, GLint> read_attachment_size() {
  GLint type = GL_NONE;
  GLint name = 0;
  glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                                        GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
  if (type == GL_NONE) return {0, 0};
  glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                                        GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
  GLint width = 0;
  GLint height = 0;
  if (type == GL_RENDERBUFFER) {
    GLint previous = 0;
    glGetIntegerv(GL_RENDERBUFFER_BINDING, &previous);
    glBindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(name));
    glGetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_WIDTH, &width);
    glGetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_HEIGHT, &height);
    glBindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(previous));
  } else if (type == GL_TEXTURE) {
    GLint level = 0;
    GLint previous = 0;
    glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                                          GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL, &level);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &previous);
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(name));
    glGetTexLevelParameteriv(GL_TEXTURE_2D, level, GL_TEXTURE_WIDTH, &width);
    glGetTexLevelParameteriv(GL_TEXTURE_2D, level, GL_TEXTURE_HEIGHT, &height);
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(previous));
  }
  return {width, height};
}

}  // namespace

struct OffscreenGL::Impl {
  OffscreenGLOptions options;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface pbuffer = EGL_NO_SURFACE;  // only where surfaceless contexts are not supported
  std::string platform;
  int samples = 0;                       // MSAA samples in use, 0 = none
  GLuint draw_fbo = 0;                   // multisampled when samples > 0
  GLuint resolve_fbo = 0;                // single-sampled copy read back to the CPU; only when samples > 0
  GLuint renderbuffers[3] = {0, 0, 0};   // draw colour, draw depth, resolve colour (only when samples > 0)
  std::vector<std::uint8_t> bottom_up;   // glReadPixels output
  std::vector<std::uint8_t> top_down;    // what read_frame() hands out

  void make_current() const {
    if (eglMakeCurrent(display, pbuffer, pbuffer, context) != EGL_TRUE) {
      throw std::runtime_error("eglMakeCurrent failed: " + egl_error_text());
    }
  }
  void create_context();
  void create_framebuffers();
  FrameView read_bound_framebuffer();
};

void OffscreenGL::Impl::create_context() {
  const SharedDisplay& shared = shared_display(options.platform);
  display = shared.display;
  platform = shared.platform;
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) throw std::runtime_error("EGL has no desktop OpenGL API");

  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                      EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                                      EGL_DEPTH_SIZE, 24, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint found = 0;
  if (eglChooseConfig(display, config_attributes, &config, 1, &found) != EGL_TRUE || found < 1) {
    throw std::runtime_error("no EGL config with RGBA8, depth 24 and desktop OpenGL: " + egl_error_text());
  }
  const std::vector<EGLint> attributes = context_attributes(options.profile);
  context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes.data());
  if (context == EGL_NO_CONTEXT) {
    throw std::runtime_error(std::string("cannot create an OpenGL ") + profile_name(options.profile) +
                             " context: " + egl_error_text());
  }

  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  const bool surfaceless = extensions != nullptr && std::strstr(extensions, "EGL_KHR_surfaceless_context") != nullptr;
  if (!surfaceless) {
    const EGLint pbuffer_attributes[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    pbuffer = eglCreatePbufferSurface(display, config, pbuffer_attributes);
    if (pbuffer == EGL_NO_SURFACE) throw std::runtime_error("cannot create a pbuffer: " + egl_error_text());
  }
  make_current();
}

void OffscreenGL::Impl::create_framebuffers() {
  const int w = options.width;
  const int h = options.height;
  GLint most_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &most_samples);
  samples = chosen_samples(options.samples, reinterpret_cast<const char*>(glGetString(GL_RENDERER)), most_samples);
  glGenRenderbuffers(samples > 0 ? 3 : 2, renderbuffers);
  glGenFramebuffers(1, &draw_fbo);

  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers[0]);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers[1]);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffers[1]);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("the drawing framebuffer is incomplete");
  }
  // A multisampled picture is resolved into a plain one before it is read; a plain one is read directly.
  if (samples > 0) {
    glGenFramebuffers(1, &resolve_fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers[2]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers[2]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("the read-back framebuffer is incomplete");
    }
  }
  check_gl("framebuffer creation");
  const auto bytes = static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4U;
  bottom_up.resize(bytes);
  top_down.resize(bytes);
}

OffscreenGL::OffscreenGL(OffscreenGLOptions options) : impl_(std::make_unique<Impl>()) {
  if (options.width <= 0 || options.height <= 0 || options.width > 16384 || options.height > 16384) {
    throw std::runtime_error("bad off-screen size " + std::to_string(options.width) + "x" +
                             std::to_string(options.height));
  }
  impl_->options = std::move(options);
  try {
    impl_->create_context();
    impl_->create_framebuffers();
  } catch (...) {
    if (impl_->context != EGL_NO_CONTEXT) {
      eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(impl_->display, impl_->context);
    }
    if (impl_->pbuffer != EGL_NO_SURFACE) eglDestroySurface(impl_->display, impl_->pbuffer);
    throw;
  }
  begin_frame();
}

OffscreenGL::~OffscreenGL() {
  impl_->make_current();
  glDeleteFramebuffers(1, &impl_->draw_fbo);
  glDeleteFramebuffers(1, &impl_->resolve_fbo);
  glDeleteRenderbuffers(3, impl_->renderbuffers);
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(impl_->display, impl_->context);
  if (impl_->pbuffer != EGL_NO_SURFACE) eglDestroySurface(impl_->display, impl_->pbuffer);
  eglReleaseThread();
}

void OffscreenGL::begin_frame() {
  impl_->make_current();
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->draw_fbo);
  glViewport(0, 0, impl_->options.width, impl_->options.height);
}

FrameView OffscreenGL::read_frame() {
  const int w = impl_->options.width;
  const int h = impl_->options.height;
  // Resolve a multisampled picture into the single-sampled FBO and read that; read a plain one directly.
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->draw_fbo);
  if (impl_->samples > 0) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, impl_->resolve_fbo);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->resolve_fbo);
  }
  const FrameView frame = impl_->read_bound_framebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->draw_fbo);
  return frame;
}

FrameView OffscreenGL::read_framebuffer(unsigned int framebuffer) {
  const int w = impl_->options.width;
  const int h = impl_->options.height;
  // Errors the caller's renderer left behind are not this read's to report.
  while (glGetError() != GL_NO_ERROR) {
  }
  const std::string what = "read_framebuffer(" + std::to_string(framebuffer) + ")";
  if (framebuffer == 0 || glIsFramebuffer(framebuffer) != GL_TRUE) {
    throw std::runtime_error(what + ": not a framebuffer object of this context");
  }
  // The caller's framebuffer is checked, then copied (and resolved, if multisampled) into this context's
  // own single-sampled one, which is read like read_frame()'s.
  const auto fail = [&](const std::string& why) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    throw std::runtime_error(what + ": " + why);
  };
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  if (glCheckFramebufferStatus(GL_READ_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) fail("the framebuffer is incomplete");
  const auto [attached_w, attached_h] = read_attachment_size();
  if (attached_w < w || attached_h < h) {
    fail("its colour attachment is " + std::to_string(attached_w) + "x" + std::to_string(attached_h) +
         ", smaller than the context's " + std::to_string(w) + "x" + std::to_string(h));
  }
  const GLuint copy = impl_->samples > 0 ? impl_->resolve_fbo : impl_->draw_fbo;
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, copy);
  // A blit honours the scissor test, which renderers (MuJoCo's among them) leave enabled.
  const GLboolean scissor = glIsEnabled(GL_SCISSOR_TEST);
  glDisable(GL_SCISSOR_TEST);
  glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  if (scissor == GL_TRUE) glEnable(GL_SCISSOR_TEST);
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    char text[128];
    std::snprintf(text, sizeof text, "OpenGL error 0x%04x copying it (a multisampled one must be exactly %dx%d)",
                  error, w, h);
    fail(text);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, copy);
  const FrameView frame = impl_->read_bound_framebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  return frame;
}

FrameView OffscreenGL::Impl::read_bound_framebuffer() {
  const int w = options.width;
  const int h = options.height;
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  // GL's first row is the bottom one; hand out the top row first.
  const auto row_bytes = static_cast<std::size_t>(w) * 4U;
  for (int y = 0; y < h; ++y) {
    std::memcpy(top_down.data() + static_cast<std::size_t>(y) * row_bytes,
                bottom_up.data() + static_cast<std::size_t>(h - 1 - y) * row_bytes, row_bytes);
  }
  return FrameView{top_down.data(), w, h, row_bytes};
}

int OffscreenGL::width() const { return impl_->options.width; }
int OffscreenGL::height() const { return impl_->options.height; }
int OffscreenGL::samples() const { return impl_->samples; }
GLProfile OffscreenGL::profile() const { return impl_->options.profile; }

std::string OffscreenGL::renderer() const {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string msaa = impl_->samples > 0 ? std::to_string(impl_->samples) + "x MSAA" : "no MSAA";
  return std::string(name != nullptr ? name : "unknown") + " via " + impl_->platform + ", " + msaa;
}

}  // namespace rfbsim
