// Stage 5 of the bake, rasterize: the map in square tiles, each with the low-poly triangles whose
// UV bounding box touches it, so a tile's samples are tested only against those.
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh.h"
#include "core/rasterize.h"

namespace nmbake {

// Texels per tile side (the trace doubles it up to 4 samples: tile_side in pipeline/bake.cpp).
constexpr int kTileSide = 16;

struct TileBins {
  int side = 16;  // texels per tile side
  int tiles_x = 0, tiles_y = 0;
  std::vector<TexelTriangle> texel_tris;  // per low-poly triangle (setup_texel_triangle)
  // The triangles of tile i (y * tiles_x + x) are tris[start[i]] .. tris[start[i + 1] - 1], in
  // increasing order: of two covering one sample, the lower index wins.
  std::vector<std::uint32_t> start, tris;

  std::size_t count() const { return start.empty() ? 0 : start.size() - 1; }
  std::size_t tile_of(int x, int y) const { return std::size_t(y / side) * std::size_t(tiles_x) + std::size_t(x / side); }
};

// One UDIM tile of the low-poly's layout to bin alone (udim.h): the triangles t with
// tile_of[t] == id, their UVs moved by (-u, -v) into the unit square before the texel set-up.
// For a UV in [u, u + 1] (u >= 1) the float subtraction is exact (Sterbenz), so the tile bins, bit
// for bit, as the mesh whose UVs were moved by that integer offset would bin in 0-1. A triangle
// reaching beyond its tile is cut at the map's edge like any triangle beyond 0-1.
struct UvTileFilter {
  const std::vector<std::int32_t>* tile_of = nullptr;  // per low-poly triangle: its tile's id, or -1 for none
  std::int32_t id = 0;
  int u = 0, v = 0;  // the tile covers UV [u, u + 1] x [v, v + 1]
};

// The bins of the low-poly's layout in a width x height map, tiles of `side` texels; with `only`,
// of that UDIM tile's triangles alone (the others get an invalid TexelTriangle and no bin).
TileBins bin_triangles(const Mesh& low, int width, int height, int side, const UvTileFilter* only = nullptr);

}  // namespace nmbake
