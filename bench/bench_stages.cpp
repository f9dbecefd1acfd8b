#include "bench_stages.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>

#include "core/parallel.h"
#include "pipeline/bake_stages.h"
#include "pipeline/trace.h"

namespace nmbake::bench {

std::vector<raycast::Ray> tile_rays(const Prepared& s, const TileBins& bins, const RaySetup& setup,
                                    const std::vector<glm::dvec2>& offsets, int width, int height) {
  // Slot (k * side + y) * side + x holds sample k of the tile's texel (x, y): its triangle (the
  // lowest index that covers it) and barycentrics. The rays come texel by texel.
  struct Slot {
    std::int32_t tri = -1;
    double b[3] = {0, 0, 0};
  };
  const int side = bins.side;
  const std::size_t texels = std::size_t(side) * std::size_t(side);
  std::vector<Slot> slots(texels * offsets.size());
  std::vector<raycast::Ray> out;
  const auto emit = [&](const Slot& slot) {
    raycast::Ray rays[2];
    double base[2];
    float lo[2], hi[2];
    const int n = sample_rays(s, std::size_t(slot.tri), slot.b, setup, rays, base, lo, hi);
    out.insert(out.end(), rays, rays + n);
  };
  for (std::size_t tile = 0; tile < bins.count(); ++tile) {
    const int tx0 = int(tile % std::size_t(bins.tiles_x)) * side, ty0 = int(tile / std::size_t(bins.tiles_x)) * side;
    std::fill(slots.begin(), slots.end(), Slot{});
    for (std::uint32_t bi = bins.start[tile]; bi < bins.start[tile + 1]; ++bi) {
      const std::uint32_t t = bins.tris[bi];
      const TexelTriangle& tt = bins.texel_tris[t];
      for (int y = std::max(tt.ymin, ty0); y <= std::min({tt.ymax, ty0 + side - 1, height - 1}); ++y)
        for (int x = std::max(tt.xmin, tx0); x <= std::min({tt.xmax, tx0 + side - 1, width - 1}); ++x)
          for (std::size_t k = 0; k < offsets.size(); ++k) {
            Slot& slot = slots[k * texels + std::size_t(y - ty0) * std::size_t(side) + std::size_t(x - tx0)];
            if (slot.tri < 0 && covers(tt, sample_point(x, y, offsets[k].x, offsets[k].y), slot.b)) slot.tri = std::int32_t(t);
          }
    }
    for (std::size_t i = 0; i < texels; ++i)
      for (std::size_t k = 0; k < offsets.size(); ++k)
        if (slots[k * texels + i].tri >= 0) emit(slots[k * texels + i]);
  }
  return out;
}

BakeRays bake_rays(const Mesh& low, const Mesh& high, const BakeOptions& o) {
  check_bake_inputs(low, high, nullptr, o);
  BakeResult result;
  TraceInputs in;
  std::string stage;
  prepare_trace(low, high, nullptr, o, worker_threads(o.threads), in, result, stage);
  const TileBins bins = bin_triangles(low, o.width, o.height, trace_tile_side(o));
  return {tile_rays(in.s, bins, in.rays, sample_offsets(o.samples), o.width, o.height), result.stats};
}

BakeStats trace_by_texel(const Mesh& low, const Mesh& high, const BakeOptions& o) {
  check_bake_inputs(low, high, nullptr, o);
  const int threads = worker_threads(o.threads);
  BakeResult result;
  std::vector<std::uint8_t> disagree;
  allocate_outputs(o, result, disagree, threads);
  TraceInputs in;
  std::string stage;
  prepare_trace(low, high, nullptr, o, threads, in, result, stage);
  BakeStats& st = result.stats;
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = process_cpu_seconds();
  const TileBins bins = bin_triangles(low, o.width, o.height, trace_tile_side(o));
  trace_and_shade(in.s, in.scene, bins, in.rays, o, threads, {result.map, result.coverage, result.miss_mask, disagree}, st);
  st.trace.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  st.trace.cpu_seconds = process_cpu_seconds() - cpu0;
  return st;
}

}  // namespace nmbake::bench
