// A GLSL program from its two shaders' sources (GLSL 3.30 core; the version line is added), for the
// renderer and the overlays. Needs a current GL context.
#pragma once

#include <epoxy/gl.h>

namespace nmview {

// `prelude`: GLSL functions put before the fragment shader's source (shaders::kLighting, ...).
// Throws nmbake::OutputError naming `name` with the compiler's or linker's log when a shader does
// not compile or the program does not link.
GLuint link_program(const char* vertex, const char* fragment, const char* name, const char* prelude = "");

}  // namespace nmview
