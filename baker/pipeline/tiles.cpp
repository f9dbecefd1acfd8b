#include "pipeline/tiles.h"

namespace nmbake {

TileBins bin_triangles(const Mesh& low, int width, int height, int side, const UvTileFilter* only) {
  TileBins b;
  b.side = side;
  b.tiles_x = (width + side - 1) / side;
  b.tiles_y = (height + side - 1) / side;
  const std::size_t tile_count = std::size_t(b.tiles_x) * std::size_t(b.tiles_y);
  b.texel_tris.resize(low.triangle_count());
  b.start.assign(tile_count + 1, 0);
  auto for_each_tile = [&](const TexelTriangle& tt, auto&& fn) {
    if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) return;
    for (int ty = tt.ymin / side; ty <= tt.ymax / side; ++ty)
      for (int tx = tt.xmin / side; tx <= tt.xmax / side; ++tx) fn(std::size_t(ty) * std::size_t(b.tiles_x) + std::size_t(tx));
  };
  const glm::vec2 shift = only ? glm::vec2(float(only->u), float(only->v)) : glm::vec2(0.0f);
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    if (only && (*only->tile_of)[t] != only->id) continue;  // left invalid: no bin
    b.texel_tris[t] = setup_texel_triangle(low.corner_uv(t, 0) - shift, low.corner_uv(t, 1) - shift, low.corner_uv(t, 2) - shift,
                                           width, height);
    for_each_tile(b.texel_tris[t], [&](std::size_t i) { ++b.start[i + 1]; });
  }
  for (std::size_t i = 0; i < tile_count; ++i) b.start[i + 1] += b.start[i];
  b.tris.resize(b.start[tile_count]);
  std::vector<std::uint32_t> fill(b.start.begin(), b.start.end() - 1);
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for_each_tile(b.texel_tris[t], [&](std::size_t i) { b.tris[fill[i]++] = std::uint32_t(t); });
  return b;
}

}  // namespace nmbake
