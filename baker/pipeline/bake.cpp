#include "pipeline/bake.h"

#include "pipeline/bake_stages.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <thread>
#include <utility>

#include "core/stopwatch.h"
#include "core/parallel.h"
#include "pipeline/bvh.h"
#include "pipeline/distances.h"
#include "pipeline/map_set.h"
#include "core/memory_budget.h"
#include "pipeline/pad.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"
#include "pipeline/select.h"
#include "pipeline/tiles.h"
#include "pipeline/trace.h"

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

namespace {

// Refuses coordinates, and ray starts, beyond kMaxCoordinate (exit 2).
void check_coordinate_range(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt) {
  auto largest = [](const Mesh& m) {
    float l = 0.0f;
    for (const glm::vec3& p : m.positions) l = std::max({l, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    return double(l);
  };
  auto refuse = [](const std::string& what, double value) {
    char text[300];
    std::snprintf(text, sizeof text, "%s %.3g from the origin; a bake takes coordinates up to %.0e (scale or move the meshes)",
                  what.c_str(), value, kMaxCoordinate);
    throw InputError(text);
  };
  const double low_largest = largest(low), cage_largest = cage ? largest(*cage) : 0.0;
  for (const auto& [m, l] : {std::pair{&low, low_largest}, std::pair{&high, largest(high)}, std::pair{cage, cage_largest}})
    if (m && l > kMaxCoordinate) refuse(m->source + ": coordinates reach", l);
  const double front = std::max(0.0f, opt.front), rear = std::max(0.0f, opt.rear);
  const double starts = std::max(low_largest, cage_largest) + front + rear;
  if (starts > kMaxCoordinate) {
    char what[120];
    std::snprintf(what, sizeof what, "%s %.3g: rays would start or end up to", front >= rear ? "--front" : "--rear",
                  std::max(front, rear));
    refuse(what, starts);
  }
}

}  // namespace

// Options and inputs a bake refuses (bake.h).
void check_bake_inputs(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt, std::uint64_t maps,
                       const std::string& what) {
  validate_options(opt);
  if (!low.has_uvs()) throw InputError(low.source + ": the low-poly mesh has no UVs");
  if (low.triangle_count() == 0) throw InputError(low.source + ": no faces");
  if (high.triangle_count() == 0) throw InputError(high.source + ": no faces");
  if (cage && (cage->triangle_count() != low.triangle_count() || cage->positions.size() != low.positions.size() ||
               cage->position_index != low.position_index))
    throw InputError(cage->source + ": the cage must have the low-poly's topology (" + std::to_string(cage->triangle_count()) +
                     " triangles, " + std::to_string(cage->positions.size()) + " vertices; " + low.source + " has " +
                     std::to_string(low.triangle_count()) + " and " + std::to_string(low.positions.size()) + ")");
  check_coordinate_range(low, high, cage, opt);
  {
    // Saturating: absurd counts of maps are refused, never wrapped round.
    const std::uint64_t one = estimate_bake_bytes(opt);
    const std::uint64_t need = maps > 1 && one > UINT64_MAX / maps ? UINT64_MAX : one * maps;
    const std::uint64_t avail = opt.memory_limit ? opt.memory_limit : memory_budget_bytes();
    if (need > avail)
      throw ResourceError("--size " + std::to_string(opt.width) + "x" + std::to_string(opt.height) + what + " needs about " +
                          std::to_string(need >> 20) + " MiB for its buffers but only " + std::to_string(avail >> 20) +
                          " MiB are available");
  }
}

// One map's buffers (bake_stages.h).
void allocate_outputs(const BakeOptions& opt, BakeResult& result, std::vector<std::uint8_t>& disagree, int threads) {
  const std::size_t texels = std::size_t(opt.width) * std::size_t(opt.height);
  result.map = Image(opt.width, opt.height, 3, Image::Unset{});  // the trace writes the covered texels, padding the rest
  touch_pages(threads, result.map.pixels.data(), result.map.pixels.size() * sizeof(float));
  touch_storage(threads, storage_for(result.coverage, texels));
  result.coverage.assign(texels, 0);
  if (opt.miss_mask) result.miss_mask = Image(opt.width, opt.height, 1, 0.0f);
  if (opt.samples > 1) {
    touch_storage(threads, storage_for(disagree, texels));
    disagree.assign(texels, 0);
  }
}

std::vector<glm::dvec2> sample_offsets(int samples) {
  std::vector<glm::dvec2> out;
  if (samples <= 1) return {glm::dvec2(0.5, 0.5)};
  const int k = int(std::lround(std::sqrt(double(samples))));
  if (k * k == samples) {
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) out.push_back({(i + 0.5) / k, (j + 0.5) / k});
    return out;
  }
  for (int i = 0; i < samples; ++i) {
    // Hammersley: x stratified in n strata, y the base-2 radical inverse, shifted off the edges.
    std::uint32_t b = std::uint32_t(i);
    b = (b << 16) | (b >> 16);
    b = ((b & 0x55555555u) << 1) | ((b & 0xAAAAAAAAu) >> 1);
    b = ((b & 0x33333333u) << 2) | ((b & 0xCCCCCCCCu) >> 2);
    b = ((b & 0x0F0F0F0Fu) << 4) | ((b & 0xF0F0F0F0u) >> 4);
    b = ((b & 0x00FF00FFu) << 8) | ((b & 0xFF00FF00u) >> 8);
    double y = double(b) * (1.0 / 4294967296.0) + 0.5 / samples;
    if (y >= 1.0) y -= 1.0;
    out.push_back({(i + 0.5) / samples, y});
  }
  return out;
}

std::uint64_t estimate_bake_bytes(const BakeOptions& o) {
  const std::uint64_t texels = std::uint64_t(std::max(o.width, 0)) * std::uint64_t(std::max(o.height, 0));
  // map (3 floats) + coverage (1 byte) + padding transform (one int) + optional miss mask.
  std::uint64_t per_texel =
      12 + 1 + (o.padding > 0 ? 4 : 0) + (o.miss_mask ? 4 : 0) + (o.suspect_mask ? 4 : 0) + (o.samples > 1 ? 1 : 0);
  for (MapKind k : o.maps.maps)  // each extra map's floats (and ao's, thickness's error)
    if (k != MapKind::normal)
      per_texel += 4u * std::uint64_t(map_image_channels(k)) + (k == MapKind::ao || k == MapKind::thickness ? 4 : 0);
  if (o.maps.ao_rays_auto) {  // --ao-rays auto: each texel's rays (allocate_map_targets' ao_rays, thickness_rays)
    if (o.maps.wants(MapKind::ao) || o.maps.wants(MapKind::bent_normal)) per_texel += 4;
    if (o.maps.wants(MapKind::thickness)) per_texel += 4;
  }
  return texels * per_texel;
}

// Secondary rays (AO, bent normals, thickness) meet triangles no primary ray reaches: the BVH then
// holds every triangle.
static bool culls_far(const BakeOptions& opt) { return opt.cull_far && !opt.maps.wants_rays(); }

void announce_stage(const BakeOptions& opt, const char* stage) {
  if (opt.on_stage) opt.on_stage(stage);
}

// The select and BVH stages (bake_stages.h).
BvhSource select_and_build(const Mesh& high, const ReachMode& mode, const BakeOptions& opt, int threads, TraceInputs& in,
                           BakeStats& st, std::string& stage) {
  const Prepared& s = in.s;
  BvhCache* const cache = opt.bvh_cache;
  const std::uint64_t content = cache ? bvh_content(s, high) : 0;
  const KeptBvh* const reuse = find_kept_bvh(cache, s, content);
  const bool keep = cache && !cache->kept;
  const double margin = mode.probing ? mode.reach * 1.01 + 1e-6 * s.diagonal : ray_margin(s, mode.any_cage, opt.front, opt.rear);
  in.selection = reuse ? reuse->selection : select_high(s, high, culls_far(opt) && !keep ? margin : -1.0, threads);
  const std::size_t count = in.selection.count(high);
  announce_stage(opt, "building the BVH");
  stage = "building the BVH of " + std::to_string(count) + " high-poly triangles";
  build_high_scene(in.scene, s, high, in.selection.kept, reuse ? reuse->quality : bvh_quality_for(opt, count), opt.threads,
                   reuse ? reuse->scene : nullptr, !keep);
  st.select.high_duplicates_skipped = in.selection.duplicates_skipped;
  st.bvh.reused = reuse != nullptr;
  if (reuse) ++cache->reused;
  if (keep)
    cache->kept =
        std::make_shared<const KeptBvh>(KeptBvh{content, s.centre, s.diagonal, in.selection, in.scene.scene, in.scene.quality});
  return reuse ? BvhSource::reused : keep ? BvhSource::kept : BvhSource::built;
}

// The narrow stage (bake_stages.h).
void narrow_and_rebuild(const Mesh& high, const ReachMode& mode, const BakeOptions& opt, int threads, const BakeResult& result,
                        TraceInputs& in) {
  const BakeStats& st = result.stats;
  if (narrow_high(in.s, high, mode.any_cage, st.distances.front, st.distances.rear, result.vertex_search, in.selection, threads))
    build_high_scene(in.scene, in.s, high, in.selection.kept, bvh_quality_for(opt, in.selection.kept.size()), opt.threads,
                     nullptr, true);
}

// The stages before the trace, in order (bake_stages.h).
void prepare_trace(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt, int threads, TraceInputs& in,
                   BakeResult& result, std::string& stage) {
  BakeStats& st = result.stats;
  announce_stage(opt, "preparing");
  stage = "preparing " + std::to_string(low.triangle_count()) + " low-poly and " + std::to_string(high.triangle_count()) +
          " high-poly triangles";
  st.prepare.low_triangles = low.triangle_count();
  st.prepare.high_triangles = high.triangle_count();
  auto t0 = Clock::now();
  in.s = prepare(low, high, cage, st);
  const ReachMode mode = ReachMode::of(opt, cage, in.s);
  st.prepare.seconds = seconds_since(t0);

  t0 = Clock::now();
  const BvhSource source = select_and_build(high, mode, opt, threads, in, st, stage);
  st.bvh.seconds = seconds_since(t0);

  t0 = Clock::now();
  announce_stage(opt, "measuring distances");
  stage = "measuring the ray distances";
  measure_reach(mode, low, opt, threads, in.s, in.scene, result);
  st.distances.seconds = seconds_since(t0);

  if (culls_far(opt) && mode.probing && source == BvhSource::built) {
    t0 = Clock::now();
    stage = "building the BVH of the reachable high-poly triangles";
    narrow_and_rebuild(high, mode, opt, threads, result, in);
    st.bvh.seconds += seconds_since(t0);
  }
  if (opt.maps.wants_rays()) {
    // The secondary rays' own BVH (raycast.h), over the triangles the trace sees.
    t0 = Clock::now();
    stage = "building the BVH of the secondary rays";
    in.scene.scene->prepare_secondary_rays();
    st.bvh.seconds += seconds_since(t0);
  }
  st.bvh.quality = quality_name(in.scene.quality);
  st.select.high_triangles_culled = high.triangle_count() - in.scene.triangles;
  in.rays.front = st.distances.front;
  in.rays.rear = st.distances.rear;
  in.rays.cage = mode.any_cage;
  in.rays.closest = opt.policy == RayPolicy::closest;
  in.rays.diagonal = in.s.diagonal;
}

std::shared_ptr<const TraceInputs> holding(std::shared_ptr<const TraceInputs> inputs, std::shared_ptr<const Mesh> high) {
  if (!inputs) return inputs;
  const auto both = std::make_shared<std::pair<std::shared_ptr<const TraceInputs>, std::shared_ptr<const Mesh>>>(
      std::move(inputs), std::move(high));
  return {both, both->first.get()};  // owns both, points to the inputs
}

// Tiles of 32 x 32 texels up to 4 samples, else 16 x 16: a triangle's rows within a tile are
// longer with the larger ones (less set-up per texel), and a tile's samples stay within the cache
// with the smaller.
int trace_tile_side(const BakeOptions& opt) { return opt.samples <= 4 ? 2 * kTileSide : kTileSide; }

void validate_options(const BakeOptions& o) {
  // As --size takes it: N for a square map, WxH otherwise.
  const std::string size = std::to_string(o.width) + (o.width == o.height ? "" : "x" + std::to_string(o.height));
  if (o.width < 1 || o.height < 1) throw UsageError("--size must be at least 1 texel per side, got " + size);
  if (o.width > kMaxMapSide || o.height > kMaxMapSide)
    throw ResourceError("--size " + size + " refused: the largest supported side is " + std::to_string(kMaxMapSide) + " texels");
  if (o.samples < 1 || o.samples > kMaxSamples)
    throw UsageError("--samples must be between 1 and " + std::to_string(kMaxSamples) + ", got " + std::to_string(o.samples));
  if (o.adaptive) {
    const int k = int(std::lround(std::sqrt(double(o.samples))));
    if (o.samples < 4 || k * k != o.samples)
      throw UsageError("--samples auto refines texels with a square number of samples (16, 64, ...), got " +
                       std::to_string(o.samples));
    if (!(o.max_error_deg > 0.0 && o.max_error_deg <= 90.0))
      throw UsageError("--max-error must be an angle in degrees above 0 and at most 90");
  }
  if (o.padding < 0 || o.padding > kMaxMapSide)
    throw UsageError("--padding must be between 0 and " + std::to_string(kMaxMapSide) + ", got " + std::to_string(o.padding));
  if (o.threads < 0 || o.threads > kMaxThreads)
    throw UsageError("--threads must be between 0 and " + std::to_string(kMaxThreads) + ", got " + std::to_string(o.threads));
  for (const auto& [d, name] : {std::pair{o.front, "--front"}, std::pair{o.rear, "--rear"}})
    if (!(d < kMaxDistance))
      throw UsageError(std::string(name) + " must be a distance >= 0 in scene units");  // NaN, infinite, huge
  if (o.space == NormalSpace::object && o.green_down) throw UsageError("--green down applies to tangent-space maps only");
  const MapOptions& m = o.maps;
  if (m.maps.empty()) throw UsageError("--maps names no map");
  for (std::size_t i = 0; i < m.maps.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (m.maps[i] == m.maps[j]) throw UsageError(std::string("--maps: ") + map_name(m.maps[i]) + " is given twice");
  if (m.ao_rays < 1 || m.ao_rays > kMaxAoRays)
    throw UsageError("--ao-rays must be between 1 and " + std::to_string(kMaxAoRays) + ", got " + std::to_string(m.ao_rays));
  if (m.ao_rays_auto && !(m.max_ao_error > 0.0 && m.max_ao_error < 0.5))
    throw UsageError("--max-ao-error must be a standard error above 0 and below 0.5");
  if (m.ao_rays_auto && (m.ao_rays_max < 1 || m.ao_rays_max > kMaxAoRays))
    throw UsageError("the most rays of --ao-rays auto must be between 1 and " + std::to_string(kMaxAoRays));
  for (const auto& [d, name] :
       {std::pair{m.ao_distance, "--ao-distance"}, std::pair{m.thickness_distance, "--thickness-distance"},
        std::pair{m.curvature_scale, "--curvature-scale"}})
    if (!(d >= 0.0 && d < kMaxDistance)) throw UsageError(std::string(name) + " must be above 0 (0: automatic)");
  if (m.height_range_given && !(std::isfinite(m.height_min) && std::isfinite(m.height_max) && m.height_min < m.height_max))
    throw UsageError("--height-range A:B needs finite A below B");
}

// The stages in order (README "Layout"): prepare, select, BVH, distances (and a narrower
// selection once they are known), rasterize, trace and shade, pad. Loading and writing are the
// caller's (io/).
BakeResult bake_normal_map(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt) {
  if (!share_origin(low, high, cage)) return bake_on_low_origin(bake_normal_map, low, high, cage, opt);
  check_bake_inputs(low, high, cage, opt);
  const int threads = worker_threads(opt.threads);
  const std::string texels = std::to_string(opt.width) + "x" + std::to_string(opt.height) + " texels, " +
                             std::to_string(opt.samples) + (opt.samples == 1 ? " sample" : " samples");
  std::string stage = "allocating the map (" + texels + ")";
  try {
    BakeResult result;
    BakeStats& st = result.stats;
    std::vector<std::uint8_t> disagree;  // per texel: its samples disagree (suspect), with several samples
    const bool extra = opt.maps.wants_extra();
    // The other maps' raw values and the curvature, made while the stages before the trace run.
    MapTargets map_out;
    std::vector<float> curvature;
    OutputAllocation outputs([&opt, &map_out, &curvature, &high, extra] {
      if (!extra) return;
      map_out = allocate_map_targets(opt.maps, opt.width, opt.height);
      curvature = map_curvature(opt, high);
    });
    const auto kept = std::make_shared<TraceInputs>();
    TraceInputs& in = *kept;
    prepare_trace(low, high, cage, opt, threads, in, result, stage);

    announce_stage(opt, "tracing");
    auto t0 = Clock::now();
    const double cpu0 = process_cpu_seconds();
    const TileBins bins = bin_triangles(low, opt.width, opt.height, trace_tile_side(opt));
    stage = "allocating the map (" + texels + ")";
    allocate_outputs(opt, result, disagree, threads);
    stage = "tracing (" + texels + ")";
    outputs.wait();
    MapInputs map_in;
    if (extra) map_in = make_map_inputs(opt, in.s, in.scene, in.selection, high, std::move(curvature));
    trace_and_shade(
        in.s, in.scene, bins, in.rays, opt, threads,
        {result.map, result.coverage, result.miss_mask, disagree, extra ? &map_in : nullptr, extra ? &map_out : nullptr}, st);
    st.trace.seconds = seconds_since(t0);
    st.trace.cpu_seconds = process_cpu_seconds() - cpu0;

    announce_stage(opt, "padding");
    stage = "padding (" + texels + ")";
    t0 = Clock::now();
    if (extra)
      result.maps = finish_maps(opt, in.s, high, map_in, map_ranges(opt, in.s, {&map_out}, {&result.coverage}), map_out,
                                result.coverage, threads);
    pad_map(opt, disagree, threads, result);
    st.pad.seconds = seconds_since(t0);
    if (opt.keep_trace) result.trace_inputs = kept;
    return result;
  } catch (const std::bad_alloc&) {
    throw ResourceError("out of memory while " + stage);
  }
}

}  // namespace nmbake
