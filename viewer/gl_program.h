// What the renderer and the overlays both make in GL: a GLSL program from its two shaders' sources
// (GLSL 3.30 core; the version line is added) and an image as an RGB texture. Need a current GL context.
#pragma once

#include <string>

#include <epoxy/gl.h>

#include "core/image.h"

namespace nmview {

// `prelude`: GLSL functions put before the fragment shader's source (shaders::kLighting, ...).
// Throws nmbake::OutputError naming `name` with the compiler's or linker's log when a shader does
// not compile or the program does not link.
GLuint link_program(const char* vertex, const char* fragment, const char* name, const char* prelude = "");

// How a texture is sampled: smooth (mipmapped, linear); exact (nearest, no mipmaps: every sample is
// one texel's value, the ID maps); texels_magnified (mipmapped when minified, nearest when magnified:
// a mask's painted texel is one it marks, not a blend reaching into the next island).
enum class TextureSampling { smooth, exact, texels_magnified };

// `image` as a repeating RGB texture (texture_set.h display_rgb: rows flipped so that texture t =
// mesh v, grey repeated), 16-bit storage (16-bit maps exact; 8-bit ones too). Throws
// nmbake::OutputError ("<what> is WxH, larger than this OpenGL's texture limit N") for an image over
// the GL texture limit.
GLuint upload_rgb_texture(const nmbake::Image& image, const std::string& what, TextureSampling sampling);

}  // namespace nmview
