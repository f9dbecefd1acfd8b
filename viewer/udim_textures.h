// The GL side of UDIM tiles (udim_tiles.h): each map's tiles as one texture array (a layer per
// tile found), each triangle's tile as an integer texture read with gl_PrimitiveID, and a table of
// the layer of every tile per map. The low-poly's fragment shader (shaders.h kLowFragment through
// udim_shader_prelude) then samples the face's tile at its UVs minus the tile's corner, clamped to
// the tile's edge (no bleeding from the next tile), and draws a face whose tile has no file of the
// normal map in kMissingTileColour, unlit. Needs a current OpenGL 3.3 core context.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/maps.h"
#include "udim_tiles.h"

namespace nmview {

class Renderer;
struct Scene;

// GLSL put before the low-poly's fragment shader: the uniforms and
// `vec4 map_texel(sampler2D whole, sampler2DArray tiles, int which, vec2 uv, out bool found)`
// (which: 0 the normal map, 1 ao, 2 the map shown), and kMissingTile.
std::string udim_shader_prelude();

// Gives the UDIM samplers of a linked program using udim_shader_prelude their own texture units
// (kUdimFirstUnit on), once after linking: no two samplers of different types may share a unit,
// even unused. UDIM stays off (u_udim 0) until UdimTextures::bind.
void set_udim_sampler_units(unsigned program);
constexpr int kUdimFirstUnit = 10;  // units 10 to 14; the renderer's own maps use 0 to 2

class UdimTextures {
 public:
  // `face_cells`: each triangle's cell (face_udim_cells) in the drawn index order. Throws
  // nmbake::ResourceError when the GL cannot hold them.
  explicit UdimTextures(const std::vector<std::int32_t>& face_cells);
  ~UdimTextures();
  UdimTextures(const UdimTextures&) = delete;
  UdimTextures& operator=(const UdimTextures&) = delete;

  // Uploads `kind`'s tiles (one size, check_tile_sizes) as a texture array, replacing any of that
  // kind; `exact`: nearest filtering, no mipmaps (ID maps). Throws nmbake::OutputError for tiles
  // over the GL's texture or layer limits, nmbake::ResourceError when out of memory.
  void add(nmbake::MapKind kind, const std::vector<UdimTileImage>& tiles, bool exact);
  // Binds the arrays and tables to their units for `program` (in use) and turns UDIM on; `shown`:
  // the map the "shown" sampler reads.
  void bind(unsigned program, nmbake::MapKind shown) const;

 private:
  unsigned face_texture_ = 0, layer_texture_ = 0;
  unsigned arrays_[nmbake::kMapKinds] = {};
  std::vector<std::int32_t> layers_;  // kMapKinds rows of kUdimCells: the tile's layer, -1 none
};

// Gives `renderer` the scene's UDIM tiles (Renderer::add_udim_map), when the scene has them.
void upload_udim_tiles(Renderer& renderer, const Scene& scene);

}  // namespace nmview
