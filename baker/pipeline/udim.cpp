#include "pipeline/udim.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "core/stopwatch.h"
#include "core/parallel.h"
#include "core/rasterize.h"
#include "pipeline/bake_stages.h"
#include "pipeline/map_set.h"
#include "pipeline/pad.h"
#include "pipeline/tiles.h"
#include "pipeline/trace.h"

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;

// The tile holding triangle t's UV centroid as u + 10 v, or -1 when none does (NaN fails every
// comparison, so a non-finite UV lands in no tile).
int centroid_cell(const Mesh& low, std::size_t t) {
  const glm::dvec2 c =
      (glm::dvec2(low.corner_uv(t, 0)) + glm::dvec2(low.corner_uv(t, 1)) + glm::dvec2(low.corner_uv(t, 2))) / 3.0;
  const double u = std::floor(c.x), v = std::floor(c.y);
  if (!(u >= 0.0 && u < kUdimColumns && v >= 0.0 && v < kUdimRows)) return -1;
  return int(u) + kUdimColumns * int(v);
}

bool straddles(const Mesh& low, std::size_t t, int u, int v) {
  for (int k = 0; k < 3; ++k) {
    const glm::vec2 uv = low.corner_uv(t, k);
    if (!(uv.x >= float(u) && uv.x <= float(u + 1) && uv.y >= float(v) && uv.y <= float(v + 1))) return true;
  }
  return false;
}

// Texel centres covered by the triangles of tile `id` (listed in `tris`), moved into 0-1, in a
// width x height map; `mask` (width x height, zeros) is left zeroed again.
std::size_t count_tile_texels(const Mesh& low, const std::vector<std::uint32_t>& tris, const UdimTile& tile, int width,
                              int height, std::vector<std::uint8_t>& mask) {
  const glm::vec2 shift(float(tile.u), float(tile.v));
  std::size_t covered = 0;
  std::vector<TexelTriangle> setups;
  setups.reserve(tris.size());
  for (std::uint32_t t : tris) {
    setups.push_back(setup_texel_triangle(low.corner_uv(t, 0) - shift, low.corner_uv(t, 1) - shift, low.corner_uv(t, 2) - shift,
                                          width, height));
    const TexelTriangle& tri = setups.back();
    if (!tri.valid()) continue;
    for (int y = tri.ymin; y <= tri.ymax; ++y)
      for (int x = tri.xmin; x <= tri.xmax; ++x) {
        double bary[3];
        std::uint8_t& m = mask[std::size_t(y) * std::size_t(width) + std::size_t(x)];
        if (m || !covers(tri, sample_point(x, y, 0.5, 0.5), bary)) continue;
        m = 1;
        ++covered;
      }
  }
  // Only the boxes the triangles touched hold ones: cheaper than clearing the whole mask per tile.
  for (const TexelTriangle& tri : setups)
    if (tri.valid())
      for (int y = tri.ymin; y <= tri.ymax; ++y)
        if (tri.xmax >= tri.xmin)
          std::fill_n(mask.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(width) + std::size_t(tri.xmin)),
                      tri.xmax - tri.xmin + 1, std::uint8_t(0));
  return covered;
}

// Per-object counts summed element by element (the tiles' vectors have the objects' length).
void add_counts(std::vector<std::uint64_t>& total, const std::vector<std::uint64_t>& tile) {
  if (total.size() < tile.size()) total.resize(tile.size(), 0);
  for (std::size_t i = 0; i < tile.size(); ++i) total[i] += tile[i];
}

// The tiles' trace and padding stats summed into `total` (UdimBake::stats).
void sum_tile_stats(const std::vector<TileBake>& tiles, BakeStats& total) {
  double dsum = 0.0;
  bool any_hit = false;
  for (const TileBake& tb : tiles) {
    const BakeStats& s = tb.result.stats;
    total.trace.rays += s.trace.rays;
    total.trace.hits += s.trace.hits;
    total.trace.misses += s.trace.misses;
    total.trace.samples_covered += s.trace.samples_covered;
    total.trace.overlapping_samples += s.trace.overlapping_samples;
    total.trace.backface_skips += s.trace.backface_skips;
    total.trace.hits_facing_away += s.trace.hits_facing_away;
    total.trace.samples_unmatched += s.trace.samples_unmatched;
    add_counts(total.trace.low_object_samples, s.trace.low_object_samples);
    add_counts(total.trace.low_object_hits, s.trace.low_object_hits);
    add_counts(total.trace.high_object_hits, s.trace.high_object_hits);
    total.trace.texels_total += s.trace.texels_total;
    total.trace.texels_covered += s.trace.texels_covered;
    total.pad.texels_padded += s.pad.texels_padded;
    total.pad.texels_facing_away += s.pad.texels_facing_away;
    total.pad.suspect_texels += s.pad.suspect_texels;
    total.trace.seconds += s.trace.seconds;
    total.trace.cpu_seconds += s.trace.cpu_seconds;
    total.pad.seconds += s.pad.seconds;
    if (!s.trace.hits) continue;
    total.trace.hit_distance_min =
        any_hit ? std::min(total.trace.hit_distance_min, s.trace.hit_distance_min) : s.trace.hit_distance_min;
    total.trace.hit_distance_max =
        any_hit ? std::max(total.trace.hit_distance_max, s.trace.hit_distance_max) : s.trace.hit_distance_max;
    dsum += s.trace.hit_distance_mean * double(s.trace.hits);
    any_hit = true;
  }
  if (total.trace.hits) total.trace.hit_distance_mean = dsum / double(total.trace.hits);
  total.trace.coverage = total.trace.texels_total ? double(total.trace.texels_covered) / double(total.trace.texels_total) : 0.0;
  total.pad.suspect_share =
      total.trace.texels_covered ? double(total.pad.suspect_texels) / double(total.trace.texels_covered) : 0.0;
}

}  // namespace

std::size_t UdimLayout::triangles_beyond_first() const {
  std::size_t n = 0;
  for (const UdimTile& t : tiles) n += t.number == kUdimFirst ? 0 : t.triangles;
  return n;
}

std::size_t UdimLayout::texels_beyond_first() const {
  std::size_t n = 0;
  for (const UdimTile& t : tiles) n += t.number == kUdimFirst ? 0 : t.texels;
  return n;
}

UdimLayout find_udim_tiles(const Mesh& low, int width, int height) {
  UdimLayout out;
  const std::size_t tris = low.triangle_count();
  std::vector<std::int32_t> cell(tris);
  std::vector<std::size_t> per_cell(std::size_t(kUdimColumns) * kUdimRows, 0);
  for (std::size_t t = 0; t < tris; ++t) {
    cell[t] = centroid_cell(low, t);
    if (cell[t] < 0) ++out.outside_triangles;
    else ++per_cell[std::size_t(cell[t])];
  }
  // Tiles by increasing number: cell u + 10 v is tile 1001 + u + 10 v, so cell order is number order.
  std::vector<std::int32_t> index_of_cell(per_cell.size(), -1);
  for (std::size_t c = 0; c < per_cell.size(); ++c) {
    if (!per_cell[c]) continue;
    index_of_cell[c] = std::int32_t(out.tiles.size());
    UdimTile tile;
    tile.u = int(c) % kUdimColumns;
    tile.v = int(c) / kUdimColumns;
    tile.number = udim_number(tile.u, tile.v);
    tile.triangles = per_cell[c];
    out.tiles.push_back(tile);
  }
  out.tile_of.resize(tris);
  for (std::size_t t = 0; t < tris; ++t) {
    out.tile_of[t] = cell[t] < 0 ? -1 : index_of_cell[std::size_t(cell[t])];
    if (out.tile_of[t] < 0) continue;
    UdimTile& tile = out.tiles[std::size_t(out.tile_of[t])];
    if (straddles(low, t, tile.u, tile.v)) ++tile.straddling, ++out.straddling_triangles;
  }
  if (width <= 0 || height <= 0 || out.tiles.empty()) return out;
  try {
    std::vector<std::vector<std::uint32_t>> members(out.tiles.size());
    for (std::size_t t = 0; t < tris; ++t)
      if (out.tile_of[t] >= 0) members[std::size_t(out.tile_of[t])].push_back(std::uint32_t(t));
    std::vector<std::uint8_t> mask(std::size_t(width) * std::size_t(height), 0);
    for (std::size_t i = 0; i < out.tiles.size(); ++i)
      out.tiles[i].texels = count_tile_texels(low, members[i], out.tiles[i], width, height, mask);
  } catch (const std::bad_alloc&) {
    throw ResourceError("out of memory while counting the texels of " + std::to_string(out.tiles.size()) + " UDIM tiles (" +
                        std::to_string(width) + "x" + std::to_string(height) + ")");
  }
  return out;
}

UdimBake bake_udim_tiles(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt) {
  if (!share_origin(low, high, cage)) return bake_on_low_origin(bake_udim_tiles, low, high, cage, opt);
  const UdimLayout layout = low.has_uvs() ? find_udim_tiles(low) : UdimLayout{};  // no UVs: check_bake_inputs says so
  const std::size_t n = layout.tiles.size();
  check_bake_inputs(low, high, cage, opt, std::max<std::size_t>(n, 1),
                    n > 1 ? " for " + std::to_string(n) + " UDIM tiles" : std::string());
  if (n == 0)
    throw InputError(low.source + ": no triangle has its UV centroid in a UDIM tile (u 0 to 10, v 0 to " +
                     std::to_string(kUdimRows) + "): nothing to bake");
  const int threads = worker_threads(opt.threads);
  const std::string texels = std::to_string(opt.width) + "x" + std::to_string(opt.height) + " texels, " +
                             std::to_string(opt.samples) + (opt.samples == 1 ? " sample" : " samples");
  const std::string allocating = "allocating the maps of " + std::to_string(n) + " UDIM tiles (" + texels + " each)";
  std::string stage = allocating;
  try {
    UdimBake out;
    out.tiles.resize(n);
    std::vector<std::vector<std::uint8_t>> disagree(n);  // per tile, per texel: its samples disagree
    const bool extra = opt.maps.wants_extra();
    std::vector<MapTargets> map_out(extra ? n : 0);  // per tile, the other maps' raw values
    std::vector<float> curvature;
    OutputAllocation outputs([&opt, &map_out, &curvature, &high, extra] {
      for (MapTargets& t : map_out) t = allocate_map_targets(opt.maps, opt.width, opt.height);
      if (extra) curvature = map_curvature(opt, high);
    });
    BakeResult shared;
    const auto kept = std::make_shared<TraceInputs>();
    TraceInputs& in = *kept;
    prepare_trace(low, high, cage, opt, threads, in, shared, stage);

    // The extra maps: what they read, once for every tile (after the allocation's curvature).
    MapInputs map_in;
    if (extra) {
      outputs.wait();
      map_in = make_map_inputs(opt, in.s, in.scene, in.selection, high, std::move(curvature));
    }

    // Trace: every tile with the shared scene, its own bins. Progress runs over all tiles.
    announce_stage(opt, "tracing");
    BakeOptions tile_opt = opt;
    for (std::size_t i = 0; i < n; ++i) {
      TileBake& tb = out.tiles[i];
      tb.tile = layout.tiles[i];
      BakeStats& st = tb.result.stats;
      st = shared.stats;
      st.prepare.uv_outside_triangles = tb.tile.straddling;
      st.prepare.uv_outside_entirely_triangles = 0;
      stage = "tracing UDIM tile " + std::to_string(tb.tile.number) + " (" + texels + ")";
      if (opt.progress) tile_opt.progress = [&opt, i, n](double f) { return opt.progress((double(i) + f) / double(n)); };
      const auto t0 = Clock::now();
      const double cpu0 = process_cpu_seconds();
      const UvTileFilter only{&layout.tile_of, std::int32_t(i), tb.tile.u, tb.tile.v};
      const TileBins bins = bin_triangles(low, opt.width, opt.height, trace_tile_side(opt), &only);
      {  // each tile's buffers just before its trace; the other maps' while the stages before the trace ran
        const std::string tracing = stage;
        stage = allocating;
        allocate_outputs(opt, tb.result, disagree[i], threads);
        if (i == 0) outputs.wait();
        stage = tracing;
      }
      trace_and_shade(in.s, in.scene, bins, in.rays, tile_opt, threads,
                      {tb.result.map, tb.result.coverage, tb.result.miss_mask, disagree[i], extra ? &map_in : nullptr,
                       extra ? &map_out[i] : nullptr},
                      st);
      st.trace.seconds = seconds_since(t0);
      st.trace.cpu_seconds = process_cpu_seconds() - cpu0;
    }

    announce_stage(opt, "padding");
    MapRanges ranges;
    if (extra) {
      std::vector<const MapTargets*> raw;
      std::vector<const std::vector<std::uint8_t>*> coverage;
      for (std::size_t i = 0; i < n; ++i) raw.push_back(&map_out[i]), coverage.push_back(&out.tiles[i].result.coverage);
      ranges = map_ranges(opt, in.s, raw, coverage);
    }
    for (std::size_t i = 0; i < n; ++i) {
      TileBake& tb = out.tiles[i];
      stage = "padding UDIM tile " + std::to_string(tb.tile.number) + " (" + texels + ")";
      const auto t0 = Clock::now();
      if (extra) tb.result.maps = finish_maps(opt, in.s, high, map_in, ranges, map_out[i], tb.result.coverage, threads);
      pad_map(opt, disagree[i], threads, tb.result);
      tb.result.stats.pad.seconds = seconds_since(t0);
      std::vector<std::uint8_t>().swap(disagree[i]);
    }

    out.stats = shared.stats;
    out.stats.prepare.uv_outside_triangles = layout.straddling_triangles;
    out.stats.prepare.uv_outside_entirely_triangles = layout.outside_triangles;
    sum_tile_stats(out.tiles, out.stats);
    out.outside_triangles = layout.outside_triangles;
    out.straddling_triangles = layout.straddling_triangles;
    out.cage_positions = std::move(shared.cage_positions);
    out.vertex_rear = std::move(shared.vertex_rear);
    out.vertex_search = std::move(shared.vertex_search);
    if (opt.keep_trace) out.trace_inputs = kept;
    return out;
  } catch (const std::bad_alloc&) {
    throw ResourceError("out of memory while " + stage);
  }
}

std::vector<ErrorEstimate> estimate_udim_errors(const Mesh& low, const BakeOptions& opt, const UdimBake& bake,
                                                const ErrorEstimateOptions& eo) {
  if (!bake.trace_inputs) throw std::invalid_argument("estimate_udim_errors: the bake kept no trace (BakeOptions::keep_trace)");
  const UdimLayout layout = find_udim_tiles(low);  // the bake's, tile for tile
  std::vector<ErrorEstimate> out;
  for (const TileBake& t : bake.tiles) {
    std::size_t k = 0;
    while (k < layout.tiles.size() && layout.tiles[k].number != t.tile.number) ++k;
    if (k == layout.tiles.size()) throw std::logic_error("estimate_udim_errors: the bake's tiles are not the mesh's");
    const UvTileFilter filter{&layout.tile_of, std::int32_t(k), layout.tiles[k].u, layout.tiles[k].v};
    ErrorEstimateOptions tile_options = eo;
    tile_options.tile = &filter;
    out.push_back(estimate_bake_error(low, *bake.trace_inputs, opt, t.result, tile_options));
  }
  return out;
}

ErrorEstimate combine_estimates(const std::vector<ErrorEstimate>& tiles) {
  ErrorEstimate all;
  double sum = 0.0, qsum = 0.0;
  for (const ErrorEstimate& e : tiles) {
    sum += e.mean_deg * double(e.texels);
    qsum += e.quantization_mean_deg * double(e.texels);
    all.texels += e.texels;
    all.samples = std::max(all.samples, e.samples);
    all.seconds += e.seconds;
    all.p95_deg = std::max(all.p95_deg, e.p95_deg);
    all.max_deg = std::max(all.max_deg, e.max_deg);
    all.quantization_max_deg = std::max(all.quantization_max_deg, e.quantization_max_deg);
  }
  if (all.texels) {
    all.mean_deg = sum / double(all.texels);
    all.quantization_mean_deg = qsum / double(all.texels);
  }
  return all;
}

}  // namespace nmbake
