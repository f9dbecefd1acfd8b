#include "core/uv_overlap.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/rasterize.h"

namespace nmbake {

namespace {

constexpr int kBandRows = 16;  // rows a chunk of work counts

// Triangle t's UVs, moved with UDIM into the unit square of the tile of its UV centroid (`tile`:
// u + 10 v). False when it lies in no tile (u below 0 or from 10 on, v below 0, NaN).
bool tile_uvs(const Mesh& mesh, std::size_t t, bool udim, glm::vec2 uv[3], int& tile) {
  for (int c = 0; c < 3; ++c) uv[c] = mesh.corner_uv(t, c);
  tile = 0;
  if (!udim) return true;
  const glm::dvec2 centre = (glm::dvec2(uv[0]) + glm::dvec2(uv[1]) + glm::dvec2(uv[2])) / 3.0;
  if (!(centre.x >= 0.0 && centre.x < 10.0 && centre.y >= 0.0 && centre.y < 1e6)) return false;
  const double tu = std::floor(centre.x), tv = std::floor(centre.y);
  tile = int(tu) + 10 * int(tv);
  for (int c = 0; c < 3; ++c) uv[c] = glm::vec2(glm::dvec2(uv[c]) - glm::dvec2(tu, tv));
  return true;
}

// The bands of rows a triangle's UVs reach (a superset of the rows it covers), as [first, last];
// first > last when none.
std::pair<int, int> bands_reached(const glm::vec2 uv[3], int height) {
  double lo = 1e300, hi = -1e300;
  for (int c = 0; c < 3; ++c) {
    const double y = (1.0 - double(uv[c].y)) * height;
    lo = std::min(lo, y);
    hi = std::max(hi, y);
  }
  if (!(lo <= hi) || hi < -1.0 || lo > height + 1.0) return {1, 0};
  const int first = int(std::max(0.0, std::floor(lo) - 1.0)), last = int(std::min(double(height - 1), std::floor(hi) + 1.0));
  return {first / kBandRows, last / kBandRows};
}

}  // namespace

UvOverlap measure_uv_overlap(const Mesh& mesh, int width, int height, bool udim, int threads) {
  UvOverlap result;
  result.width = width;
  result.height = height;
  if (width <= 0 || height <= 0 || !mesh.has_uvs()) return result;
  // Per tile, per band of rows, the triangles that reach it in index order (4 bytes an entry: a
  // triangle is set up again in each band it reaches, so nothing the size of a triangle's setup is
  // kept per triangle).
  const std::size_t bands = (std::size_t(height) + kBandRows - 1) / kBandRows;
  std::map<int, std::vector<std::vector<std::uint32_t>>> tiles;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    glm::vec2 uv[3];
    int tile = 0;
    if (!tile_uvs(mesh, t, udim, uv, tile)) continue;
    const auto [first, last] = bands_reached(uv, height);
    if (first > last) continue;
    auto& lists = tiles[tile];
    if (lists.empty()) lists.resize(bands);
    for (int b = first; b <= last; ++b) lists[std::size_t(b)].push_back(std::uint32_t(t));
  }
  const std::size_t row = std::size_t(width);
  for (const auto& entry : tiles) {
    const std::vector<std::vector<std::uint32_t>>& lists = entry.second;
    std::vector<UvOverlap> band_counts(bands);
    parallel_chunks(threads, bands, 1, [&](std::size_t b0, std::size_t b1) {
      std::vector<std::uint16_t> depth(std::size_t(kBandRows) * row);
      for (std::size_t b = b0; b < b1; ++b) {
        const int y_lo = int(b) * kBandRows, y_hi = std::min(height, int(b + 1) * kBandRows) - 1;
        std::fill(depth.begin(), depth.end(), std::uint16_t(0));
        for (std::uint32_t t : lists[b]) {
          glm::vec2 uv[3];
          int tile = 0;
          tile_uvs(mesh, t, udim, uv, tile);
          const TexelTriangle tri = setup_texel_triangle(uv[0], uv[1], uv[2], width, height);
          if (!tri.valid()) continue;
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
