// SPDX-License-Identifier: GPL-2.0-or-later
// One GL program from a vertex and a fragment shader's source: the compile-and-link both GL users of render/
// (GlRenderer, GlHudLayer) need. Needs a current GL 3.3 core context.
#pragma once

#include <cstdint>
#include <string>

namespace rfbsim::sim {

/// Compiles both shaders and links them into a program, returning its name (a GLuint; the caller deletes
/// it with glDeleteProgram). Throws std::runtime_error starting with `what` and holding the compiler's or
/// linker's log when either step fails; nothing is left allocated then.
std::uint32_t link_gl_program(const char* vertex_source, const char* fragment_source, const std::string& what);

}  // namespace rfbsim::sim
