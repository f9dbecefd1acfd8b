// UDIM tiles (issue 20, item 4): bake_udim_tiles bakes one map per occupied tile of the low-poly's
// UV layout with one run of the stages before the trace. Each tile's map must equal, bit for bit,
// the single-map bake of the same meshes with that tile's UVs moved into 0-1 and the other
// triangles' UVs moved out of the map; overlap is counted per tile; triangles in no tile are
// counted; degenerate and mirrored UVs in a tile stay finite.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/rasterize.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "pipeline/tiles.h"
#include "pipeline/udim.h"
#include "test_support.h"

using namespace nmbake;

namespace {

using test::bake_options;

using nmbake::test::kPi;

// The low-poly's surface, a gentle dome, and the high-poly's: the dome with bumps on it.
double dome(double x, double y) { return 0.15 * (1.0 - 0.5 * x * x - 0.3 * y * y); }
glm::dvec3 dome_normal(double x, double y) { return glm::normalize(glm::dvec3(0.15 * x, 0.09 * y, 1.0)); }
double bumps(double x, double y) { return dome(x, y) + 0.03 * std::sin(3 * kPi * x) * std::sin(2 * kPi * y); }
glm::dvec3 bumps_normal(double x, double y) {
  const double hx = -0.15 * x + 0.03 * 3 * kPi * std::cos(3 * kPi * x) * std::sin(2 * kPi * y);
  const double hy = -0.09 * y + 0.03 * 2 * kPi * std::sin(3 * kPi * x) * std::cos(2 * kPi * y);
  return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
}

Mesh bumpy_high() { return test::make_height_field(120, 120, bumps, bumps_normal); }
// The bumps alone, over the plane z = 0 (for test::make_grid's flat low-polys).
Mesh flat_bumpy_high() {
  return test::make_height_field(
      120, 120, [](double x, double y) { return bumps(x, y) - dome(x, y); },
      [](double x, double y) {
        const double hx = 0.03 * 3 * kPi * std::cos(3 * kPi * x) * std::sin(2 * kPi * y);
        const double hy = 0.03 * 2 * kPi * std::sin(3 * kPi * x) * std::cos(2 * kPi * y);
        return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
      });
}

// The mesh with a UV of its own for every corner: f(triangle, corner position).
Mesh with_corner_uvs(const Mesh& m, const std::function<glm::vec2(std::size_t, glm::vec3)>& f) {
  Mesh out = m;
  out.uvs.clear();
  out.uv_index.clear();
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      out.uvs.push_back(f(t, m.corner_position(t, c)));
      out.uv_index.push_back(std::uint32_t(3 * t + c));
    }
  return out;
}

float centroid_x(const Mesh& m, std::size_t t) {
  return (m.corner_position(t, 0).x + m.corner_position(t, 1).x + m.corner_position(t, 2).x) / 3.0f;
}

// The three-tile scene: the dome cut in three strips along x, each strip an island in its own
// tile: 1001 (0, 0), 1002 (1, 0) and 1011 (0, 1), 5% inside the tile's edges.
struct Strip {
  int u, v, number;
};
const Strip kStrips[3] = {{0, 0, 1001}, {1, 0, 1002}, {0, 1, 1011}};

int strip_of(const Mesh& m, std::size_t t) {
  const float x = centroid_x(m, t);
  return x < -1.0f / 3.0f ? 0 : x < 1.0f / 3.0f ? 1 : 2;
}

Mesh three_tile_low() {
  const Mesh grid = test::make_height_field(12, 12, dome, dome_normal);
  return with_corner_uvs(grid, [&](std::size_t t, glm::vec3 p) {
    const int s = strip_of(grid, t);
    const double x0 = -1.0 + s * 2.0 / 3.0;
    return glm::vec2(float(kStrips[s].u + 0.05 + 0.9 * (p.x - x0) / (2.0 / 3.0)),
                     float(kStrips[s].v + 0.05 + 0.9 * (p.y + 1.0) / 2.0));
  });
}

// The single-map reference for tile (u, v): that tile's triangles' UVs moved into 0-1 (the same
// float subtraction the UDIM bake makes), the others' moved 20 to the right, out of the map. The
// positions, normals and every UV difference within a tile are unchanged, so the stages before the
// trace see the same scene.
Mesh single_tile_reference(const Mesh& low, const UdimLayout& layout, std::size_t tile) {
  Mesh ref = low;
  const glm::vec2 shift(float(layout.tiles[tile].u), float(layout.tiles[tile].v));
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      glm::vec2& uv = ref.uvs[ref.uv_index[3 * t + c]];
      uv = layout.tile_of[t] == std::int32_t(tile) ? uv - shift : uv + glm::vec2(20.0f, 0.0f);
    }
  return ref;
}

bool same_bits(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels || a.pixels.size() != b.pixels.size()) return false;
  return a.pixels.empty() || std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

std::size_t differing_values(const Image& a, const Image& b) {
  if (a.pixels.size() != b.pixels.size()) return std::max(a.pixels.size(), b.pixels.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) n += std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(float)) != 0;
  return n;
}

void expect_same_bake(const BakeResult& tile, const BakeResult& single, const std::string& what) {
  EXPECT_TRUE(same_bits(tile.map, single.map)) << what << ": " << differing_values(tile.map, single.map) << " map values differ";
  EXPECT_TRUE(tile.coverage == single.coverage) << what;
  EXPECT_TRUE(same_bits(tile.miss_mask, single.miss_mask)) << what;
  EXPECT_TRUE(same_bits(tile.suspect_mask, single.suspect_mask)) << what;
  const BakeStats &a = tile.stats, &b = single.stats;
  EXPECT_EQ(a.trace.rays, b.trace.rays) << what;
  EXPECT_EQ(a.trace.hits, b.trace.hits) << what;
  EXPECT_EQ(a.trace.misses, b.trace.misses) << what;
  EXPECT_EQ(a.trace.samples_covered, b.trace.samples_covered) << what;
  EXPECT_EQ(a.trace.overlapping_samples, b.trace.overlapping_samples) << what;
  EXPECT_EQ(a.trace.texels_covered, b.trace.texels_covered) << what;
  EXPECT_EQ(a.pad.texels_padded, b.pad.texels_padded) << what;
  EXPECT_EQ(a.pad.suspect_texels, b.pad.suspect_texels) << what;
  EXPECT_EQ(a.trace.hit_distance_min, b.trace.hit_distance_min) << what;
  EXPECT_EQ(a.trace.hit_distance_mean, b.trace.hit_distance_mean) << what;
  EXPECT_EQ(a.trace.hit_distance_max, b.trace.hit_distance_max) << what;
  EXPECT_EQ(a.distances.front, b.distances.front) << what;
  EXPECT_EQ(a.distances.rear, b.distances.rear) << what;
}

// Covered texels whose normal leans more than ~8 degrees from the flat (0, 0, 1): the map holds
// the bumps, not a flat default.
std::size_t bumpy_texels(const BakeResult& r) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) n += r.coverage[i] && r.map.pixels[3 * i + 2] < 0.995f;
  return n;
}

}  // namespace

TEST(Udim, ThreeTilesEqualThreeSingleTileBakes) {
  const Mesh low = three_tile_low(), high = bumpy_high();
  const UdimLayout layout = find_udim_tiles(low);
  ASSERT_EQ(layout.tiles.size(), 3u);
  BakeOptions automatic = bake_options(64, 1, 4);  // the automatic cage: distances measured per vertex
  automatic.miss_mask = automatic.suspect_mask = true;
  BakeOptions closest = bake_options(48, 1, 4);  // fixed distances, 4 samples, both ways
  closest.front = closest.rear = 0.1f;
  closest.samples = 4;
  closest.policy = RayPolicy::closest;
  // A cage file: the automatic cage of the first bake, moved out a little more, with --rear.
  Mesh cage = low;
  BakeOptions with_cage = bake_options(40, 1, 4);
  with_cage.rear = 0.08f;
  with_cage.threads = 1;
  for (int run = 0; run < 3; ++run) {
    const BakeOptions& o = run == 0 ? automatic : run == 1 ? closest : with_cage;
    const Mesh* cage_used = run == 2 ? &cage : nullptr;
    const UdimBake udim = bake_udim_tiles(low, high, cage_used, o);
    ASSERT_EQ(udim.tiles.size(), 3u);
    if (run == 0) {
      ASSERT_EQ(udim.cage_positions.size(), low.positions.size());
      for (std::size_t v = 0; v < low.positions.size(); ++v)
        cage.positions[v] = udim.cage_positions[v] + 0.01f * glm::vec3(dome_normal(low.positions[v].x, low.positions[v].y));
    }
    for (std::size_t i = 0; i < 3; ++i) {
      const TileBake& tb = udim.tiles[i];
      EXPECT_EQ(tb.tile.number, kStrips[i].number);
      EXPECT_EQ(tb.tile.triangles, layout.tiles[i].triangles);
      const BakeResult single = bake_normal_map(single_tile_reference(low, layout, i), high, cage_used, o);
      const std::string what = "tile " + std::to_string(tb.tile.number) + ", run " + std::to_string(run);
      expect_same_bake(tb.result, single, what);
      // Not a vacuous equality: the island covers most of its tile and carries the bumps.
      EXPECT_GT(tb.result.stats.trace.texels_covered, std::size_t(o.width * o.height) * 7 / 10) << what;
      EXPECT_GT(bumpy_texels(tb.result), tb.result.stats.trace.texels_covered / 4) << what;
      EXPECT_EQ(tb.result.stats.trace.overlapping_samples, 0u) << what;
    }
    // Each strip lies under another part of the bumps: no two maps are the same.
    EXPECT_FALSE(same_bits(udim.tiles[0].result.map, udim.tiles[1].result.map));
    EXPECT_FALSE(same_bits(udim.tiles[1].result.map, udim.tiles[2].result.map));
    // The totals are the tiles' sums.
    std::uint64_t rays = 0;
    std::size_t covered = 0;
    for (const TileBake& tb : udim.tiles) rays += tb.result.stats.trace.rays, covered += tb.result.stats.trace.texels_covered;
    EXPECT_EQ(udim.stats.trace.rays, rays);
    EXPECT_EQ(udim.stats.trace.texels_covered, covered);
    EXPECT_EQ(udim.stats.trace.texels_total, 3u * std::size_t(o.width * o.height));
    EXPECT_EQ(udim.outside_triangles, 0u);
  }
}

// A layout entirely in 1001 bakes the same map as bake_normal_map, bit for bit.
// The error estimate's re-bake of a tile (its triangles alone, UVs moved into 0-1) over the trace
// the bake kept once for all tiles (with the automatic cage) gives the tile's own texels, bit for bit.
TEST(Udim, RebakedTileTexelsMatchTheTile) {
  const Mesh low = three_tile_low(), high = bumpy_high();
  BakeOptions o = bake_options(48, 1, 4);
  o.keep_trace = true;
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  ASSERT_TRUE(udim.trace_inputs);
  const UdimLayout layout = find_udim_tiles(low);
  ASSERT_EQ(udim.tiles.size(), layout.tiles.size());
  for (std::size_t k = 0; k < udim.tiles.size(); ++k) {
    EXPECT_FALSE(udim.tiles[k].result.trace_inputs);
    const UvTileFilter filter{&layout.tile_of, std::int32_t(k), layout.tiles[k].u, layout.tiles[k].v};
    std::size_t covered = 0;
    EXPECT_EQ(test::texels_traced_otherwise(low, *udim.trace_inputs, o, udim.tiles[k].result, &covered, &filter), 0u)
        << "tile " << layout.tiles[k].number;
    EXPECT_GT(covered, 500u);
  }
  const std::vector<ErrorEstimate> e = estimate_udim_errors(low, o, udim);
  ASSERT_EQ(e.size(), udim.tiles.size());
  const ErrorEstimate all = combine_estimates(e);
  EXPECT_EQ(all.texels, e[0].texels + e[1].texels + e[2].texels);
  EXPECT_GE(all.max_deg, std::max({e[0].max_deg, e[1].max_deg, e[2].max_deg}));
}

TEST(Udim, OneTileInTheUnitSquareIsThePlainBake) {
  const Mesh low = test::make_height_field(10, 10, dome, dome_normal), high = bumpy_high();
  const BakeOptions o = bake_options(64, 1, 4);
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  ASSERT_EQ(udim.tiles.size(), 1u);
  EXPECT_EQ(udim.tiles[0].tile.number, 1001);
  const BakeResult plain = bake_normal_map(low, high, nullptr, o);
  expect_same_bake(udim.tiles[0].result, plain, "tile 1001");
  EXPECT_TRUE(udim.cage_positions == plain.cage_positions);
}

TEST(Udim, OverlapIsCountedPerTile) {
  // The dome's left and right halves mapped onto the same square: in tiles 1001 and 1002 they
  // do not overlap; both in 1001 they do.
  const Mesh grid = test::make_height_field(8, 8, dome, dome_normal), high = bumpy_high();
  auto stacked = [&](int right_tile_u) {
    return with_corner_uvs(grid, [&](std::size_t t, glm::vec3 p) {
      const bool right = centroid_x(grid, t) > 0.0f;
      return glm::vec2(float((right ? right_tile_u : 0) + 0.1 + 0.8 * (right ? p.x : p.x + 1.0)), float(0.1 + 0.4 * (p.y + 1.0)));
    });
  };
  BakeOptions o = bake_options(48, 1, 4);
  o.front = o.rear = 0.1f;
  const UdimBake apart = bake_udim_tiles(stacked(1), high, nullptr, o);
  ASSERT_EQ(apart.tiles.size(), 2u);
  EXPECT_EQ(apart.tiles[1].tile.number, 1002);
  for (const TileBake& tb : apart.tiles) {
    EXPECT_EQ(tb.result.stats.trace.overlapping_samples, 0u) << tb.tile.number;
    EXPECT_GT(tb.result.stats.trace.texels_covered, 48u * 48u / 2) << tb.tile.number;
  }
  EXPECT_EQ(apart.stats.trace.overlapping_samples, 0u);

  const Mesh together = stacked(0);
  const UdimBake one = bake_udim_tiles(together, high, nullptr, o);
  ASSERT_EQ(one.tiles.size(), 1u);
  const BakeResult plain = bake_normal_map(together, high, nullptr, o);
  EXPECT_GT(one.tiles[0].result.stats.trace.overlapping_samples, 48u * 48u / 2);
  EXPECT_EQ(one.tiles[0].result.stats.trace.overlapping_samples, plain.stats.trace.overlapping_samples);
  EXPECT_EQ(one.stats.trace.overlapping_samples, plain.stats.trace.overlapping_samples);
  EXPECT_EQ(one.tiles[0].result.stats.trace.texels_covered, apart.tiles[0].result.stats.trace.texels_covered);
}

TEST(Udim, TrianglesInNoTileAreCountedAndLeftOut) {
  const Mesh three = three_tile_low(), high = bumpy_high();
  Mesh low = three;
  std::size_t moved_right = 0, expected_outside = 0;
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    const int s = strip_of(low, t);
    glm::vec2 shift(0.0f);
    if (s == 2) shift = {-1.0f, -1.0f};                                   // 1011's strip to 1001's left: u < 0
    if (s == 1 && moved_right < 6) shift = {10.0f, 0.0f}, ++moved_right;  // beyond the 10th column
    if (shift == glm::vec2(0.0f)) continue;
    ++expected_outside;
    for (int c = 0; c < 3; ++c) low.uvs[low.uv_index[3 * t + c]] += shift;
  }
  // A triangle below v = 0 too.
  for (int c = 0; c < 3; ++c) low.uvs[low.uv_index[c]].y -= 1.0f;
  ++expected_outside;
  const UdimLayout layout = find_udim_tiles(low);
  EXPECT_EQ(layout.outside_triangles, expected_outside);
  ASSERT_EQ(layout.tiles.size(), 2u);
  EXPECT_EQ(layout.tiles[0].number, 1001);
  EXPECT_EQ(layout.tiles[1].number, 1002);
  EXPECT_EQ(layout.tiles[0].triangles + layout.tiles[1].triangles + expected_outside, low.triangle_count());

  BakeOptions o = bake_options(48, 1, 4);
  o.front = o.rear = 0.1f;
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  ASSERT_EQ(udim.tiles.size(), 2u);
  EXPECT_EQ(udim.outside_triangles, expected_outside);
  EXPECT_EQ(udim.stats.prepare.uv_outside_entirely_triangles, expected_outside);
  // What lies outside moves no other tile's texel: 1002's map is its single-tile bake.
  const BakeResult single = bake_normal_map(single_tile_reference(low, layout, 1), high, nullptr, o);
  expect_same_bake(udim.tiles[1].result, single, "tile 1002");
  // A non-finite UV lies in no tile.
  Mesh nan_uv = three;
  nan_uv.uvs[nan_uv.uv_index[0]].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(find_udim_tiles(nan_uv).outside_triangles, 1u);
}

TEST(Udim, LayoutCountsTrianglesAndTexelsPerTile) {
  const Mesh low = three_tile_low(), high = bumpy_high();
  const UdimLayout layout = find_udim_tiles(low, 64, 64);
  ASSERT_EQ(layout.tiles.size(), 3u);
  std::size_t per_strip[3] = {0, 0, 0};
  for (std::size_t t = 0; t < low.triangle_count(); ++t) ++per_strip[strip_of(low, t)];
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(layout.tiles[i].number, kStrips[i].number);
    EXPECT_EQ(layout.tiles[i].triangles, per_strip[i]);
    EXPECT_EQ(layout.tiles[i].straddling, 0u);
    // Texel centres covered: as the rasterizer counts them on the single-tile reference.
    const std::vector<std::int32_t> owner = rasterize_texel_triangles(single_tile_reference(low, layout, i), 64, 64);
    std::size_t owned = 0;
    for (std::int32_t o : owner) owned += o >= 0;
    EXPECT_EQ(layout.tiles[i].texels, owned) << layout.tiles[i].number;
    EXPECT_GT(owned, 64u * 64u * 7 / 10);
  }
  EXPECT_EQ(layout.triangles_beyond_first(), per_strip[1] + per_strip[2]);
  EXPECT_EQ(layout.texels_beyond_first(), layout.tiles[1].texels + layout.tiles[2].texels);
  // Without a size no texel is counted; with one sample the bake covers the same texels.
  EXPECT_EQ(find_udim_tiles(low).tiles[1].texels, 0u);
  BakeOptions o = bake_options(64, 1, 4);
  o.front = o.rear = 0.1f;
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(udim.tiles[i].result.stats.trace.texels_covered, layout.tiles[i].texels);
  // A bake without <UDIM> covers 1001's texels only: the rest is what the warning names.
  const BakeResult plain = bake_normal_map(low, high, nullptr, o);
  EXPECT_EQ(plain.stats.trace.texels_covered, layout.tiles[0].texels);
}

TEST(Udim, StraddlingTriangleIsCutAtItsTilesEdge) {
  // Four triangles: a quad in 1001, a triangle from u 0.7 to 1.9 (centroid in 1002) and one more
  // in 1002, above it.
  const Mesh grid = test::make_grid(2, 1, -1, 1, -0.5f, 0.5f), high = flat_bumpy_high();
  const glm::vec2 uv[4][3] = {{{0.1f, 0.1f}, {0.6f, 0.1f}, {0.6f, 0.6f}},
                              {{0.1f, 0.1f}, {0.6f, 0.6f}, {0.1f, 0.6f}},
                              {{0.7f, 0.2f}, {1.9f, 0.2f}, {1.9f, 0.8f}},
                              {{1.2f, 0.85f}, {1.5f, 0.85f}, {1.5f, 0.95f}}};
  const Mesh low = with_corner_uvs(grid, [&](std::size_t t, glm::vec3 p) {
    for (int c = 0; c < 3; ++c)
      if (grid.corner_position(t, c) == p) return uv[t][c];
    return glm::vec2(0.0f);
  });
  const UdimLayout layout = find_udim_tiles(low);
  ASSERT_EQ(layout.tiles.size(), 2u);
  EXPECT_EQ(layout.tiles[0].triangles, 2u);
  EXPECT_EQ(layout.tiles[1].triangles, 2u);
  EXPECT_EQ(layout.tiles[1].straddling, 1u);
  EXPECT_EQ(layout.straddling_triangles, 1u);

  BakeOptions o = bake_options(40, 1, 4);
  o.front = o.rear = 0.1f;
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  EXPECT_EQ(udim.stats.prepare.uv_outside_triangles, 1u);
  EXPECT_EQ(udim.tiles[1].result.stats.prepare.uv_outside_triangles, 1u);
  // 1002 holds the straddler up to its left edge; 1001 holds none of it, where the plain bake
  // (the unit square) covers its part from u = 0.7 on.
  const BakeResult plain = bake_normal_map(low, high, nullptr, o);
  std::size_t edge_1002 = 0, right_1001 = 0, right_plain = 0;
  for (int y = 0; y < 40; ++y) {
    edge_1002 += udim.tiles[1].result.coverage[std::size_t(y) * 40];
    for (int x = 30; x < 40; ++x) {  // u > 0.75
      right_1001 += udim.tiles[0].result.coverage[std::size_t(y) * 40 + std::size_t(x)];
      right_plain += plain.coverage[std::size_t(y) * 40 + std::size_t(x)];
    }
  }
  EXPECT_GT(edge_1002, 0u);
  EXPECT_EQ(right_1001, 0u);
  EXPECT_GT(right_plain, 0u);
  const BakeResult single = bake_normal_map(single_tile_reference(low, layout, 1), high, nullptr, o);
  expect_same_bake(udim.tiles[1].result, single, "tile 1002");
}

TEST(Udim, MirroredAndZeroAreaUvsInATileStayFinite) {
  // Tile 1002: a quad, the next quad with its UVs mirrored, a triangle of zero UV area; tile 1003:
  // only a zero-area triangle (occupied, nothing covered).
  const Mesh grid = test::make_grid(3, 1, -1, 1, -0.5f, 0.5f), high = flat_bumpy_high();
  const Mesh low = with_corner_uvs(grid, [&](std::size_t t, glm::vec3 p) {
    const double s = (p.x + 1.0) / 2.0 * 3.0 - double(t / 2), tv = p.y + 0.5;  // within the quad, 0-1
    switch (t / 2) {
      case 0: return glm::vec2(float(1.05 + 0.4 * s), float(0.05 + 0.4 * tv));
      case 1: return glm::vec2(float(1.95 - 0.4 * s), float(0.55 + 0.4 * tv));                 // mirrored in u
      default: return t == 4 ? glm::vec2(1.5f, 0.5f) : glm::vec2(float(2.2 + 0.3 * s), 0.5f);  // a point; a line
    }
  });
  BakeOptions o = bake_options(32, 1, 4);
  o.front = o.rear = 0.1f;
  o.samples = 4;
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  ASSERT_EQ(udim.tiles.size(), 2u);
  EXPECT_EQ(udim.tiles[0].tile.number, 1002);
  EXPECT_EQ(udim.tiles[1].tile.number, 1003);
  EXPECT_EQ(udim.stats.prepare.degenerate_uv_triangles, 2u);
  for (const TileBake& tb : udim.tiles)
    for (float c : tb.result.map.pixels) ASSERT_TRUE(std::isfinite(c)) << tb.tile.number;
  const BakeResult& mixed = udim.tiles[0].result;
  EXPECT_GT(mixed.stats.trace.texels_covered, 32u * 32u / 4);
  for (std::size_t i = 0; i < mixed.coverage.size(); ++i)  // the bumps lean less than 20 degrees
    EXPECT_TRUE(!mixed.coverage[i] || mixed.map.pixels[3 * i + 2] > 0.9f) << "texel " << i;
  // Mirrored and degenerate UVs included, still the single-tile bake.
  const BakeResult single = bake_normal_map(single_tile_reference(low, find_udim_tiles(low), 0), high, nullptr, o);
  expect_same_bake(mixed, single, "tile 1002");
  const BakeResult& empty = udim.tiles[1].result;
  EXPECT_EQ(empty.stats.trace.texels_covered, 0u);
  for (std::size_t i = 0; i < empty.coverage.size(); ++i) {
    ASSERT_EQ(empty.map.pixels[3 * i], 0.5f);
    ASSERT_EQ(empty.map.pixels[3 * i + 1], 0.5f);
    ASSERT_EQ(empty.map.pixels[3 * i + 2], 1.0f);
  }
}

TEST(Udim, MemoryCheckCountsEveryTile) {
  const Mesh low = three_tile_low(), high = bumpy_high();
  BakeOptions o = bake_options(64, 1, 4);
  o.front = o.rear = 0.1f;
  o.memory_limit = 2 * estimate_bake_bytes(o);  // two maps fit, three do not
  try {
    bake_udim_tiles(low, high, nullptr, o);
    ADD_FAILURE() << "three tiles baked within the memory of two";
  } catch (const ResourceError& e) {
    EXPECT_TRUE(test::contains(e.what(), "for 3 UDIM tiles")) << e.what();
  }
  o.memory_limit = 3 * estimate_bake_bytes(o);
  EXPECT_EQ(bake_udim_tiles(low, high, nullptr, o).tiles.size(), 3u);
}

TEST(Udim, StagesAnnouncedOnceAndProgressRunsOverAllTiles) {
  const Mesh low = three_tile_low(), high = bumpy_high();
  BakeOptions o = bake_options(48, 1, 4);
  std::vector<std::string> stages;
  std::vector<double> progress;
  o.on_stage = [&](const char* s) { stages.push_back(s); };
  o.progress = [&](double f) {
    progress.push_back(f);
    return true;
  };
  bake_udim_tiles(low, high, nullptr, o);
  EXPECT_EQ(stages, (std::vector<std::string>{"preparing", "building the BVH", "measuring distances", "tracing", "padding"}));
  ASSERT_FALSE(progress.empty());
  for (std::size_t i = 1; i < progress.size(); ++i) EXPECT_LE(progress[i - 1], progress[i]);
  EXPECT_GE(progress.front(), 0.0);
  EXPECT_EQ(progress.back(), 1.0);
  // Cancelling in the second tile stops the bake (a tile takes long enough for a progress call).
  o.width = o.height = 128;
  o.samples = 4;
  o.progress = [](double f) { return f < 0.5; };
  EXPECT_THROW(bake_udim_tiles(low, high, nullptr, o), Cancelled);
}

TEST(Udim, NoTriangleInAnyTileIsAnInputError) {
  Mesh low = three_tile_low();
  for (glm::vec2& uv : low.uvs) uv.x -= 12.0f;
  EXPECT_THROW(bake_udim_tiles(low, bumpy_high(), nullptr, bake_options(16, 1, 4)), InputError);
}

namespace {

// The three-tile scene as files, for the command line (normals computed from the faces).
std::string write_three_tile_scene(const std::string& dir) {
  test::write_file(dir + "/low.obj", obj_text(three_tile_low(), "three UDIM tiles"));
  test::write_file(dir + "/high.obj", obj_text(flat_bumpy_high(), "bumps"));
  return "low.obj high.obj --size 64";
}

}  // namespace

// -o with <UDIM>: one map (and mask) per tile, each the command's single-tile bake; the report's
// "udim" lists the tiles; without <UDIM> the warning names the tiles it leaves out.
TEST(UdimCommand, OneMapPerTile) {
  const std::string dir = test::scratch_dir();
  const std::string scene = write_three_tile_scene(dir);
  const test::CliRun r = test::run_nmbake(scene + " -o 'n.<UDIM>.png' --miss-mask 'm.<UDIM>.png' --report r.json", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.out, "3 UDIM tiles: 1001, 1002, 1011")) << r.out;
  const nlohmann::json& tiles = r.report["udim"]["tiles"];
  ASSERT_EQ(tiles.size(), 3u);
  const Mesh low = load_mesh(dir + "/low.obj");
  const UdimLayout layout = find_udim_tiles(low);
  for (std::size_t k = 0; k < 3; ++k) {
    const int n = layout.tiles[k].number;
    EXPECT_EQ(tiles[k]["tile"], n);
    EXPECT_EQ(tiles[k]["file"], "n." + std::to_string(n) + ".png");
    EXPECT_GT(tiles[k]["coverage"].get<double>(), 0.3);
    EXPECT_TRUE(test::exists(dir + "/m." + std::to_string(n) + ".png"));
    // The tile's map is the command's bake of the tile moved into 0-1, the rest moved away.
    test::write_file(dir + "/ref.obj", obj_text(single_tile_reference(low, layout, k), "one tile"));
    const test::CliRun single = test::run_nmbake("ref.obj high.obj --size 64 -o single.png", "", dir);
    ASSERT_EQ(single.code, 0) << single.err;
    EXPECT_TRUE(test::read_file(dir + "/n." + std::to_string(n) + ".png") == test::read_file(dir + "/single.png")) << n;
  }
  // The error estimate, per tile: each tile's map against a re-bake of its own texels.
  const test::CliRun estimated = test::run_nmbake(scene + " -o 'e.<UDIM>.png' --estimate-error --report r.json", "", dir);
  ASSERT_EQ(estimated.code, 0) << estimated.err;
  EXPECT_TRUE(test::contains(estimated.err, "error estimate: mean")) << estimated.err;
  for (const nlohmann::json& t : estimated.report["udim"]["tiles"]) {
    EXPECT_GT(t["error_estimate"]["texels"].get<int>(), 500) << t;
    EXPECT_LT(t["error_estimate"]["mean_deg"].get<double>(), 2.0) << t;
  }
  EXPECT_EQ(estimated.report["error_estimate"]["texels"].get<int>(), [&] {
    int n = 0;
    for (const nlohmann::json& t : estimated.report["udim"]["tiles"]) n += t["error_estimate"]["texels"].get<int>();
    return n;
  }());
  // Without <UDIM>: the unit square only, and the warning says what <UDIM> would add.
  const test::CliRun plain = test::run_nmbake(scene + " -o plain.png", "", dir);
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_TRUE(test::contains(plain.err, "lie in UDIM tiles 1002, 1011: -o with <UDIM>")) << plain.err;
  EXPECT_TRUE(test::read_file(dir + "/plain.png") == test::read_file(dir + "/n.1001.png"));
}

TEST(UdimCommand, TilesWhereTheyCannotGoAreRefused) {
  const std::string dir = test::scratch_dir();
  const std::string scene = write_three_tile_scene(dir);
  for (const char* args :
       {"-o 'sub<UDIM>/n.png'", "-o 'n.<UDIM>.png' --report 'r.<UDIM>.json'", "-o 'n.<UDIM>.png' --save-cage 'c.<UDIM>.obj'",
        "-o 'n.<UDIM>.png' --miss-mask m.png", "-o n.png --suspect-mask 's.<UDIM>.png'"}) {
    const test::CliRun r = test::run_nmbake(scene + " " + args, "", dir);
    EXPECT_EQ(r.code, 1) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const char* file : {"n.1001.png", "n.png", "m.png", "r.json"}) EXPECT_FALSE(test::exists(dir + "/" + file)) << args;
  }
}
