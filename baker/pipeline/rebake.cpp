// Re-baking chosen texels (bake.h, bake_texel_values), for the error estimate (error_estimate.h):
// the bake's own stages (prepare, bvh, tiles) and rays and shading (rays.h) for a list of texels;
// tests/test_error_estimate.cpp checks both agree texel for texel.
#include <algorithm>
#include <atomic>
#include <thread>

#include "core/parallel.h"
#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"
#include "pipeline/tiles.h"

namespace nmbake {

// The bake's own preparation, rays and shading (prepare, sample_rays, chosen_hit, shade_sample)
// for a list of texels; tests/test_error_estimate.cpp checks both agree texel for texel.
std::vector<glm::dvec3> bake_texel_values(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt,
                                          const BakeResult& baked, const std::vector<std::uint32_t>& texels, int samples,
                                          const UvTileFilter* tile) {
  const BakeStats& st = baked.stats;
  std::vector<glm::dvec3> out(texels.size(), glm::dvec3(0.0));
  if (texels.empty() || low.triangle_count() == 0 || high.triangle_count() == 0 || !low.has_uvs()) return out;
  const int threads = worker_threads(opt.threads);
  const int W = opt.width, H = opt.height;
  BakeStats scratch;
  Prepared s = prepare(low, high, cage, scratch);
  if (!cage && !baked.cage_positions.empty())
    attach_cage(s, baked.cage_positions, low.position_index);  // the bake's automatic cage
  const bool any_cage = !s.cage_tris.empty();
  if (any_cage) set_cage_reach(s, low, st.distances.rear, baked.vertex_rear, baked.vertex_search);
  // Few rays: a quick BVH build pays off more than a fast one to trace. All triangles: culling
  // leaves the hits unchanged.
  HighScene scene;
  build_high_scene(scene, s, high, {}, raycast::BuildQuality::low, opt.threads, nullptr, true);
  if (st.distances.high_facing == BakeStats::HighFacing::inverted)
    turn_inverted_high(s, scene, scratch.prepare.high_normals_computed);
  const RayGroups groups = ray_groups(s, scene, opt);
  raycast::HitRule rule;
  const raycast::HitRule* const hit_rule = trace_rule(scene, st.distances.backfaces_skipped, groups, rule);
  RaySetup ray_setup;
  ray_setup.front = st.distances.front;
  ray_setup.rear = st.distances.rear;
  ray_setup.cage = any_cage;
  ray_setup.closest = opt.policy == RayPolicy::closest;
  ray_setup.diagonal = s.diagonal;
  const int rays_per_sample = ray_setup.closest ? 2 : 1;

  const TileBins bins = bin_triangles(low, W, H, kTileSide, tile);  // a UDIM tile's texels: its triangles alone

  const std::vector<glm::dvec2> offsets = sample_offsets(samples);
  std::vector<std::uint8_t> covered(texels.size(), 0);  // each entry written by one thread only
  std::atomic<std::size_t> next{0};
  run_parallel(threads, [&](int) {
    struct Sample {
      std::size_t texel;  // index into `texels`
      std::uint32_t tri;
      double b[3];
    };
    std::vector<Sample> work;
    constexpr std::size_t kChunk = 64;
    // Sized for a chunk's most samples (each texel has at most one per offset); each chunk fills
    // the first work.size() * rays_per_sample rays.
    raycast::RayArrays arrays(kChunk * offsets.size() * std::size_t(rays_per_sample));
    const raycast::HitBatch hits = arrays.hits();
    std::vector<std::uint8_t> outward(rays_per_sample == 2 ? arrays.size() : 0);
    for (std::size_t i = 0; i < outward.size(); i += 2) outward[i] = 1;
    raycast::RayBatch ray_batch = arrays.rays();
    ray_batch.outward = outward.empty() ? nullptr : outward.data();
    ray_batch.coherent = true;  // a texel's samples one after another
    std::vector<float> prefer_lo(arrays.size()), prefer_hi(arrays.size());
    if (st.distances.backfaces_skipped) {
      ray_batch.prefer_lo = prefer_lo.data();
      ray_batch.prefer_hi = prefer_hi.data();
    }
    std::vector<std::uint32_t> ray_group(groups.active() ? arrays.size() : 0);  // unmatched: kNoMatch, no hit
    if (groups.active()) ray_batch.group = ray_group.data();
    std::vector<double> signed_base(arrays.size());
    for (std::size_t i0; (i0 = next.fetch_add(kChunk)) < texels.size();) {
      const std::size_t i1 = std::min(texels.size(), i0 + kChunk);
      work.clear();
      for (std::size_t i = i0; i < i1; ++i) {
        const int x = int(texels[i] % W), y = int(texels[i] / W);
        const std::size_t bin = bins.tile_of(x, y);
        for (const glm::dvec2& o : offsets)
          for (std::uint32_t bi = bins.start[bin]; bi < bins.start[bin + 1]; ++bi) {
            const std::uint32_t t = bins.tris[bi];
            Sample sm{i, t, {0, 0, 0}};
            if (!covers(bins.texel_tris[t], sample_point(x, y, o.x, o.y), sm.b)) continue;
            work.push_back(sm);
            break;
          }
      }
      for (std::size_t r = 0; r < work.size(); ++r) {
        raycast::Ray one[2];
        float lo[2], hi[2];
        const int n = sample_rays(s, work[r].tri, work[r].b, ray_setup, one, &signed_base[r * rays_per_sample], lo, hi);
        for (int j = 0; j < n; ++j) {
          const std::size_t i = r * rays_per_sample + std::size_t(j);
          arrays.set(i, one[j]);
          prefer_lo[i] = lo[j];
          prefer_hi[i] = hi[j];
          if (groups.active()) ray_group[i] = groups.low[work[r].tri];
        }
      }
      const std::size_t ray_count = work.size() * std::size_t(rays_per_sample);
      if (ray_count) scene.scene->intersect(ray_batch, hits, ray_count, hit_rule);
      for (std::size_t r = 0; r < work.size(); ++r) {
        double dist = 0.0;
        const std::size_t h = chosen_hit(hits, r * rays_per_sample, signed_base.data(), ray_setup.closest, &dist);
        out[work[r].texel] += shade_sample(s, scene, work[r].tri, work[r].b, arrays.hit(h), opt);
        covered[work[r].texel] = 1;
      }
      for (std::size_t i = i0; i < i1; ++i) {
        if (!covered[i]) continue;
        const double len = glm::length(out[i]);
        out[i] = len > 0.0 ? out[i] * (1.0 / len) : glm::dvec3(0, 0, 1);
        if (opt.space == NormalSpace::tangent && opt.green_down) out[i].y = -out[i].y;
      }
    }
  });
  return out;
}

}  // namespace nmbake
