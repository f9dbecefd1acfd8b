#include "udim_textures.h"

#include <algorithm>
#include <cstdio>

#include <epoxy/gl.h>

#include "core/errors.h"
#include "renderer.h"
#include "scene.h"
#include "texture_set.h"

namespace nmview {
namespace {

constexpr int kFaceRowLength = 1024;  // texels per row of the faces' table: the smallest GL 3.3 texture limit

GLint udim_uniform(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

void throw_on_gl_error(const std::string& what) {
  if (GLenum error = glGetError(); error == GL_OUT_OF_MEMORY)
    throw nmbake::ResourceError("out of memory uploading " + what + " to OpenGL (GL_OUT_OF_MEMORY)");
  else if (error != GL_NO_ERROR) throw nmbake::OutputError("OpenGL error " + std::to_string(error) + " while uploading " + what);
}

// An integer table as a single-channel R32I texture, read with texelFetch only.
void upload_int_table(GLuint texture, const std::vector<std::int32_t>& values, int width, int height) {
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32I, width, height, 0, GL_RED_INTEGER, GL_INT, values.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
}

}  // namespace

std::string udim_shader_prelude() {
  char colour[96];
  std::snprintf(colour, sizeof(colour), "const vec3 kMissingTile = vec3(%.3f, %.3f, %.3f);\n", double(kMissingTileColour[0]),
                double(kMissingTileColour[1]), double(kMissingTileColour[2]));
  // The face's tile comes from gl_PrimitiveID (the triangle's place in the index buffer, as
  // face_udim_cells numbers them): a per-face value needs no vertex attribute, and the merged
  // vertices stay shared across tiles. The tile is sampled on every face whether it has a file or
  // not, so that implicit derivatives stay defined (uniform control flow).
  return std::string(colour) + R"(
uniform int u_udim;                  // 1: every map is a UDIM tile array, 0: the maps as sampler2D
uniform isampler2D u_face_cells;     // triangle i at (i % 1024, i / 1024): its cell u + 10 v, -1 none
uniform isampler2D u_tile_layers;    // (cell, map kind): the tile's layer in that map's array, -1 none
uniform sampler2DArray u_map_tiles;
uniform sampler2DArray u_ao_tiles;
uniform sampler2DArray u_shown_tiles;
uniform ivec3 u_tile_rows;           // u_tile_layers' rows of the normal, ao and shown maps
vec4 map_texel(sampler2D whole, sampler2DArray tiles, int which, vec2 uv, out bool found) {
  found = true;
  if (u_udim == 0) return texture(whole, uv);
  int cell = texelFetch(u_face_cells, ivec2(gl_PrimitiveID % 1024, gl_PrimitiveID / 1024), 0).r;
  int layer = cell < 0 ? -1 : texelFetch(u_tile_layers, ivec2(cell, u_tile_rows[which]), 0).r;
  int c = max(cell, 0);
  vec4 texel = texture(tiles, vec3(uv - vec2(float(c % 10), float(c / 10)), float(max(layer, 0))));
  found = layer >= 0;
  return found ? texel : vec4(0.0);
}
)";
}

void set_udim_sampler_units(unsigned program) {
  glUseProgram(program);
  const char* names[] = {"u_face_cells", "u_tile_layers", "u_map_tiles", "u_ao_tiles", "u_shown_tiles"};
  for (int i = 0; i < 5; ++i) glUniform1i(udim_uniform(program, names[i]), kUdimFirstUnit + i);
  glUniform1i(udim_uniform(program, "u_udim"), 0);
  glUseProgram(0);
}

UdimTextures::UdimTextures(const std::vector<std::int32_t>& face_cells)
    : layers_(std::size_t(nmbake::kMapKinds) * kUdimCells, -1) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  const int rows = std::max(1, int((face_cells.size() + kFaceRowLength - 1) / kFaceRowLength));
  if (rows > max_size || kUdimCells > max_size)
    throw nmbake::ResourceError("the low-poly's " + std::to_string(face_cells.size()) +
                                " triangles are too many for this OpenGL's UDIM table (" + std::to_string(max_size) + " rows)");
  std::vector<std::int32_t> table(std::size_t(rows) * kFaceRowLength, -1);
  std::copy(face_cells.begin(), face_cells.end(), table.begin());
  glGenTextures(1, &face_texture_);
  upload_int_table(face_texture_, table, kFaceRowLength, rows);
  glGenTextures(1, &layer_texture_);
  upload_int_table(layer_texture_, layers_, kUdimCells, nmbake::kMapKinds);
  throw_on_gl_error("the faces' UDIM tiles");
}

UdimTextures::~UdimTextures() {
  glDeleteTextures(1, &face_texture_);
  glDeleteTextures(1, &layer_texture_);
  glDeleteTextures(nmbake::kMapKinds, arrays_);
}

void UdimTextures::add(nmbake::MapKind kind, const std::vector<UdimTileImage>& tiles, bool exact) {
  if (tiles.empty()) return;
  const std::string name = std::string("the ") + nmbake::map_name(kind) + " map's UDIM tiles";
  const int width = tiles.front().image.width, height = tiles.front().image.height;
  GLint max_size = 0, max_layers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (width > max_size || height > max_size || int(tiles.size()) > max_layers)
    throw nmbake::OutputError(name + ": " + std::to_string(tiles.size()) + " of " + std::to_string(width) + "x" +
                              std::to_string(height) + ", over this OpenGL's limits (" + std::to_string(max_size) +
                              " texels a side, " + std::to_string(max_layers) + " layers)");
  GLuint& array = arrays_[int(kind)];
  glDeleteTextures(1, &array);
  glGenTextures(1, &array);
  glBindTexture(GL_TEXTURE_2D_ARRAY, array);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  // 16-bit storage as the single maps (renderer.cpp upload_map): 8- and 16-bit maps stay exact.
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGB16, width, height, GLsizei(tiles.size()), 0, GL_RGB, GL_FLOAT, nullptr);
  std::int32_t* row = &layers_[std::size_t(kind) * kUdimCells];
  std::fill_n(row, kUdimCells, -1);
  for (std::size_t layer = 0; layer < tiles.size(); ++layer) {
    const std::vector<float> rgb = display_rgb(tiles[layer].image);
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, GLint(layer), width, height, 1, GL_RGB, GL_FLOAT, rgb.data());
    row[tiles[layer].number - kUdimFirstTile] = std::int32_t(layer);
  }
  if (!exact) glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, exact ? GL_NEAREST : GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, exact ? GL_NEAREST : GL_LINEAR);
  // Clamped: a tile's edge texels are its own (nmbake pads past the islands), never the next tile's.
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  upload_int_table(layer_texture_, layers_, kUdimCells, nmbake::kMapKinds);
  throw_on_gl_error(name);
}

void UdimTextures::bind(unsigned program, nmbake::MapKind shown) const {
  auto bind_unit = [](int offset, GLenum target, GLuint texture) {
    glActiveTexture(GLenum(GL_TEXTURE0 + kUdimFirstUnit + offset));
    glBindTexture(target, texture);
  };
  bind_unit(0, GL_TEXTURE_2D, face_texture_);
  bind_unit(1, GL_TEXTURE_2D, layer_texture_);
  bind_unit(2, GL_TEXTURE_2D_ARRAY, arrays_[int(nmbake::MapKind::normal)]);
  bind_unit(3, GL_TEXTURE_2D_ARRAY, arrays_[int(nmbake::MapKind::ao)]);
  bind_unit(4, GL_TEXTURE_2D_ARRAY, arrays_[int(shown)]);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(udim_uniform(program, "u_udim"), 1);
  glUniform3i(udim_uniform(program, "u_tile_rows"), int(nmbake::MapKind::normal), int(nmbake::MapKind::ao), int(shown));
}

void upload_udim_tiles(Renderer& renderer, const Scene& scene) {
  if (!scene.map_files.udim) return;
  renderer.set_udim_faces(scene.face_cells);
  renderer.add_udim_map(nmbake::MapKind::normal, scene.map_tiles);
  for (const SetMap& m : scene.set_maps) renderer.add_udim_map(m.kind, m.tiles);
}

}  // namespace nmview
