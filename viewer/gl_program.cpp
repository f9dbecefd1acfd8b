#include "gl_program.h"

#include <string>

#include "core/errors.h"

namespace nmview {
namespace {

GLuint compile_shader(GLenum type, const std::string& source, const char* name) {
  GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw nmbake::OutputError(std::string("shader ") + name + " does not compile: " + log);
  }
  return shader;
}

}  // namespace

GLuint link_program(const char* vertex, const char* fragment, const char* name, const char* prelude) {
  const std::string header = "#version 330 core\n";
  GLuint vs = compile_shader(GL_VERTEX_SHADER, header + vertex, name);
  GLuint fs = compile_shader(GL_FRAGMENT_SHADER, header + prelude + fragment, name);
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    glDeleteProgram(program);
    throw nmbake::OutputError(std::string("shader program ") + name + " does not link: " + log);
  }
  return program;
}

}  // namespace nmview
