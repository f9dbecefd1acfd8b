// UDIM tiles: one map per occupied tile of the low-poly's UV layout, in one pass over the rays.
//
// Tile (u, v) covers UV [u, u + 1) x [v, v + 1) for u in 0..9 and v in 0..99; its number is
// 1001 + u + 10 v (1001 is the unit square, 1002 the square to its right, 1011 the one above).
// A low-poly triangle belongs to the tile holding its UV centroid (the mean of its corners' UVs,
// in double; a centroid on a tile's edge belongs to the tile above or to the right). Each tile's
// map is the bake of its own triangles alone, their UVs moved by (-u, -v): a triangle reaching
// beyond its tile ("straddling") is rasterized into its own tile only, cut at the tile's edge; the
// part beyond is baked into no map. Triangles whose centroid lies in no tile (u < 0, u >= 10,
// v < 0, v >= 100, not finite) are counted and not baked.
//
// A tile's map equals, bit for bit, the map bake_normal_map gives for the same meshes with that
// tile's UVs moved into 0-1 by its integer offset and the other triangles' UVs moved out of every
// map (tests/test_udim.cpp): the stages before the trace (prepare, select, BVH, distances) read no
// UV but the tangent frames', which take UV differences, and those the exact shift keeps. Overlap
// (BakeStats::Trace::overlapping_samples) is counted per tile: islands stacked in different tiles do not
// overlap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/mesh.h"
#include "pipeline/bake.h"
#include "pipeline/error_estimate.h"

namespace nmbake {

constexpr int kUdimFirst = 1001;  // the number of tile (0, 0)
constexpr int kUdimColumns = 10;  // tiles per row: u in [0, 10)
constexpr int kUdimRows = 100;    // rows: v in [0, 100), so numbers up to 2000

inline int udim_number(int u, int v) { return kUdimFirst + u + kUdimColumns * v; }

struct UdimTile {
  int number = kUdimFirst;     // 1001 + u + 10 v
  int u = 0, v = 0;            // the tile covers UV [u, u + 1) x [v, v + 1)
  std::size_t triangles = 0;   // low-poly triangles whose UV centroid lies in the tile
  std::size_t straddling = 0;  // of those, with a corner outside the closed square [u, u + 1] x [v, v + 1]
  // Texel centres covered by the tile's triangles in a map of the size asked for (find_udim_tiles;
  // a centre covered twice counts once); 0 when no size was given.
  std::size_t texels = 0;
};

struct UdimLayout {
  std::vector<UdimTile> tiles;           // the occupied tiles (at least one triangle), by increasing number
  std::vector<std::int32_t> tile_of;     // per low-poly triangle: its index in `tiles`, or -1 (no tile)
  std::size_t outside_triangles = 0;     // triangles in no tile: not baked
  std::size_t straddling_triangles = 0;  // UdimTile::straddling summed over the tiles

  // What a bake without <UDIM> (the unit square only) leaves out that a UDIM bake bakes: the
  // triangles of every tile but 1001 and the texel centres they cover (0 without a map size).
  std::size_t triangles_beyond_first() const;
  std::size_t texels_beyond_first() const;
};

// The low-poly's occupied tiles (it must have UVs). With width and height > 0, each tile's
// covered texel centres in a map of that size too (one map-sized byte mask, reused tile by tile;
// the tiles' triangles rasterized at texel centres); with 0, none are counted.
UdimLayout find_udim_tiles(const Mesh& low, int width = 0, int height = 0);

// One tile's bake. result.stats holds the shared stages' stats (as UdimBake::stats) and this
// tile's own: rays, hits, misses, samples_covered, overlapping_samples (within this tile),
// backface_skips, hits_facing_away, hit_distance_*, texels_total (width x height),
// texels_covered, coverage, texels_padded, texels_facing_away, suspect_* (suspect_region in the
// tile's own 0-1 square), per-object counts, seconds_trace, cpu_seconds_trace, seconds_padding;
// uv_outside_triangles is the tile's straddling triangles and uv_outside_entirely_triangles 0.
// result.cage_positions, vertex_rear and vertex_search are empty (UdimBake holds them once).
struct TileBake {
  UdimTile tile;  // texels: 0 (the covered texels are result.stats.texels_covered)
  BakeResult result;
};

struct UdimBake {
  std::vector<TileBake> tiles;  // one per occupied tile, by increasing number
  // The shared stages' stats (prepare, select, BVH, distances) and the tiles' summed: rays, hits,
  // misses, samples_covered, overlapping_samples, backface_skips, hits_facing_away,
  // samples_unmatched, per-object counts, texels_total, texels_covered, texels_padded,
  // texels_facing_away, suspect_texels, seconds_trace, cpu_seconds_trace, seconds_padding;
  // coverage = texels_covered / texels_total, suspect_share over texels_covered, hit_distance_min,
  // _max over the tiles and _mean weighted by their hits; suspect_region is left 0 (it is per
  // tile). uv_outside_triangles counts the straddling triangles and uv_outside_entirely_triangles
  // those in no tile (not baked), in place of prepare's counts against the unit square.
  BakeStats stats;
  std::size_t outside_triangles = 0;      // in no tile: not baked
  std::size_t straddling_triangles = 0;   // cut at their tile's edge
  std::vector<glm::vec3> cage_positions;  // as BakeResult's
  std::vector<float> vertex_rear, vertex_search;
  std::shared_ptr<const TraceInputs> trace_inputs;  // as BakeResult's, for all tiles (the tiles' are null)
};

// Bakes every occupied tile: prepare, select, BVH and distances once, then per tile its bins, the
// trace and the padding. The stages are announced once each (options.on_stage), tracing covering
// every tile; options.progress runs from 0 to 1 over all tiles. All maps are held at once: the
// memory check asks for estimate_bake_bytes(options) times the tile count. Throws what
// bake_normal_map throws, and InputError when no triangle lies in a tile.
UdimBake bake_udim_tiles(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& options);

// The error estimate (error_estimate.h) of each tile of `bake` (made by bake_udim_tiles from `low`
// with these options and keep_trace): the tile's map against a re-bake of its texels from its own
// triangles. In the order of bake.tiles; `estimate` as for one map (its `tile` is set here).
std::vector<ErrorEstimate> estimate_udim_errors(const Mesh& low, const BakeOptions& options, const UdimBake& bake,
                                                const ErrorEstimateOptions& estimate = {});

// The tiles' estimates as one: the mean weighted by the texels compared, and the largest p95, max
// and quantisation max (an upper bound of the whole's p95); the texels and seconds summed.
ErrorEstimate combine_estimates(const std::vector<ErrorEstimate>& tiles);

}  // namespace nmbake
