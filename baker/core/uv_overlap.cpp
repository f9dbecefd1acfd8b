#include "core/uv_overlap.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "core/parallel.h"
#include "core/rasterize.h"

namespace nmbake {

namespace {

// One triangle in its tile: the UVs moved into the unit square of the tile it counts in.
struct TileTriangle {
  int tile;  // 0 without UDIM, else u + 10 v of the tile
  glm::vec2 uv[3];
};

std::vector<TileTriangle> place_triangles(const Mesh& mesh, bool udim) {
  std::vector<TileTriangle> out;
  out.reserve(mesh.triangle_count());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    TileTriangle tt{0, {mesh.corner_uv(t, 0), mesh.corner_uv(t, 1), mesh.corner_uv(t, 2)}};
    if (udim) {
      const glm::dvec2 c = (glm::dvec2(tt.uv[0]) + glm::dvec2(tt.uv[1]) + glm::dvec2(tt.uv[2])) / 3.0;
      if (!(c.x >= 0.0 && c.x < 10.0 && c.y >= 0.0 && c.y < 1e6)) continue;  // in no tile (NaN too)
      const double tu = std::floor(c.x), tv = std::floor(c.y);
      tt.tile = int(tu) + 10 * int(tv);
      for (glm::vec2& uv : tt.uv) uv = glm::vec2(glm::dvec2(uv) - glm::dvec2(tu, tv));
    }
    out.push_back(tt);
  }
  return out;
}

}  // namespace

UvOverlap measure_uv_overlap(const Mesh& mesh, int width, int height, bool udim, int threads) {
  UvOverlap result;
  result.width = width;
  result.height = height;
  if (width <= 0 || height <= 0 || !mesh.has_uvs()) return result;
  const std::vector<TileTriangle> tris = place_triangles(mesh, udim);
  std::map<int, std::vector<std::uint32_t>> by_tile;  // the triangles of each tile, in index order
  for (std::uint32_t i = 0; i < tris.size(); ++i) by_tile[tris[i].tile].push_back(i);
  const std::size_t row = std::size_t(width);
  for (const auto& [tile, members] : by_tile) {
    std::vector<TexelTriangle> setup;
    setup.reserve(members.size());
    for (std::uint32_t i : members) {
      setup.push_back(setup_texel_triangle(tris[i].uv[0], tris[i].uv[1], tris[i].uv[2], width, height));
      if (!setup.back().valid() || setup.back().xmax < setup.back().xmin) setup.pop_back();
    }
    // Rows in bands, one band per chunk: each counts its own rows over every triangle of the tile.
    const std::size_t band_rows = 16;
    const std::size_t bands = (std::size_t(height) + band_rows - 1) / band_rows;
    std::vector<UvOverlap> band_counts(bands);
    parallel_chunks(threads, bands, 1, [&](std::size_t b0, std::size_t b1) {
      std::vector<std::uint16_t> depth(band_rows * row);
      for (std::size_t b = b0; b < b1; ++b) {
        const int y_lo = int(b * band_rows), y_hi = std::min(height, int((b + 1) * band_rows)) - 1;
        std::fill(depth.begin(), depth.end(), std::uint16_t(0));
        for (const TexelTriangle& tri : setup) {
          if (tri.ymax < y_lo || tri.ymin > y_hi) continue;
          for (int y = std::max(tri.ymin, y_lo); y <= std::min(tri.ymax, y_hi); ++y)
            for (int x = tri.xmin; x <= tri.xmax; ++x) {
              double bary[3];
              if (!covers(tri, sample_point(x, y, 0.5, 0.5), bary)) continue;
              std::uint16_t& d = depth[std::size_t(y - y_lo) * row + std::size_t(x)];
              if (d < 0xffff) ++d;
            }
        }
        UvOverlap& c = band_counts[b];
        for (std::uint16_t d : depth) {
          c.covered += d >= 1;
          c.overlapped += d >= 2;
          c.stacked += d >= 3;
          c.layers += d;
        }
      }
    });
    for (const UvOverlap& c : band_counts) {
      result.covered += c.covered;
      result.overlapped += c.overlapped;
      result.stacked += c.stacked;
      result.layers += c.layers;
    }
  }
  return result;
}

}  // namespace nmbake
