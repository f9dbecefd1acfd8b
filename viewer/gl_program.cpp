#include "gl_program.h"

#include <string>
#include <vector>

#include "core/errors.h"
#include "texture_set.h"

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

GLuint upload_rgb_texture(const nmbake::Image& image, const std::string& what, TextureSampling sampling) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (image.width > max_size || image.height > max_size)
    throw nmbake::OutputError(what + " is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                              ", larger than this OpenGL's texture limit " + std::to_string(max_size));
  const std::vector<float> rgb = display_rgb(image);
  const bool exact = sampling == TextureSampling::exact;
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB16, image.width, image.height, 0, GL_RGB, GL_FLOAT, rgb.data());
  if (!exact) glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, exact ? GL_NEAREST : GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, sampling == TextureSampling::smooth ? GL_LINEAR : GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return texture;
}

}  // namespace nmview
