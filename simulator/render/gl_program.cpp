// SPDX-License-Identifier: GPL-2.0-or-later
// Shader programs: compile, link, and say why when either fails.
#include "render/gl_program.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <stdexcept>

namespace rfbsim::sim {

namespace {

GLuint compile(GLenum type, const char* source, const std::string& what) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == 0) {
    std::string log(4096, '\0');
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(what + " compile failed: " + std::string(log.c_str()));
  }
  return shader;
}

}  // namespace

std::uint32_t link_gl_program(const char* vertex_source, const char* fragment_source, const std::string& what) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source, what);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_source, what);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == 0) {
    std::string log(4096, '\0');
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(program);
    throw std::runtime_error(what + " link failed: " + std::string(log.c_str()));
  }
  return program;
}

}  // namespace rfbsim::sim
