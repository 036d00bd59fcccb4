// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::OffscreenGL: an OpenGL context without a window (EGL) rendering into a framebuffer object.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim {

/// Which OpenGL the context offers.
enum class GLProfile : std::uint8_t {
  kCore33,         ///< OpenGL 3.3 core: shaders only (sim_rfb's renderer, new code)
  kCompatibility,  ///< the newest compatibility-profile OpenGL the driver has: fixed-function calls work too
                   ///< (MuJoCo 2.x's mjr_* renderer, legacy code)
};

/// Definition of an off-screen context. New fields are added at the end, so that aggregate
/// initialisation such as {w, h, samples, platform} keeps its meaning.
struct OffscreenGLOptions {
  /// `samples` value that lets OffscreenGL choose the MSAA for the renderer it finds.
  static constexpr int kAutoSamples = -1;

  int width = 1280;   ///< FBO width in pixels (> 0)
  int height = 720;   ///< FBO height in pixels (> 0)
  /// MSAA samples (resolved before read-back); 0 or 1 = none; more than the renderer supports
  /// (GL_MAX_SAMPLES) = its maximum. kAutoSamples: 4 on a GPU, none on a software rasterizer (Mesa
  /// llvmpipe or softpipe), where 4x MSAA costs more than the rest of the frame.
  int samples = kAutoSamples;
  /// Which EGL platform to use: "auto" tries the device platform (GPUs, e.g. NVIDIA) and then Mesa's
  /// surfaceless platform (llvmpipe on machines without a GPU); or "device" / "surfaceless".
  std::string platform = "auto";
  /// Core 3.3 (the default) or compatibility; see GLProfile.
  GLProfile profile = GLProfile::kCore33;
};

/// An OpenGL context (3.3 core, or compatibility: OffscreenGLOptions::profile), current on the creating
/// thread, drawing into an FBO. Owns the context and the FBO; shares one EGL display per process with every
/// other instance. Use from the thread that created it. A renderer that brings its own framebuffer (MuJoCo's
/// mjrContext) draws there instead and hands it to read_framebuffer().
class OffscreenGL {
 public:
  /// Creates the display (once per process), context and FBO and makes the context current.
  /// Throws std::runtime_error naming the failing step (no EGL display, no config, no context).
  explicit OffscreenGL(OffscreenGLOptions options = {});
  ~OffscreenGL();
  OffscreenGL(const OffscreenGL&) = delete;
  OffscreenGL& operator=(const OffscreenGL&) = delete;

  /// Makes the context current on this thread and binds the FBO for drawing.
  void begin_frame();
  /// Resolves multisampling and reads the FBO into a reusable buffer, top row first.
  /// The view stays valid until the next read_frame() or the destructor.
  FrameView read_frame();
  /// Reads a framebuffer object that the caller rendered into itself (e.g. MuJoCo's mjrContext::offFBO),
  /// top row first, into the same reusable buffer as read_frame(). Its colour attachment 0 must be at least
  /// width() x height(), exactly that size if it is multisampled (it is resolved on the way). Leaves
  /// `framebuffer` bound (GL_FRAMEBUFFER) as the caller had it. The context must be current (begin_frame()).
  /// Throws std::runtime_error naming the GL error when the framebuffer cannot be read (unknown name,
  /// incomplete, wrong size).
  FrameView read_framebuffer(unsigned int framebuffer);

  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;
  /// MSAA samples in use (0 = none): options.samples, or what kAutoSamples chose for this renderer.
  [[nodiscard]] int samples() const;
  /// The profile the context was made with.
  [[nodiscard]] GLProfile profile() const;
  /// GL_RENDERER, the EGL platform and the MSAA in use, e.g.
  /// "llvmpipe (LLVM 15.0.6, 256 bits) via surfaceless, no MSAA".
  [[nodiscard]] std::string renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim
