// Stage 6 of the bake, trace and shade: for every tile of the map, the samples the low-poly's UV
// layout covers (rasterize), their rays (pipeline/rays.h) cast in packets onto the high-poly's BVH,
// the high-poly normal at each hit in the low-poly's tangent frame (or object space), and each
// covered texel the renormalized mean of its samples. Tiles are shared out to threads; every
// value is summed in a fixed order, so the map does not depend on the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"
#include "pipeline/texel_maps.h"
#include "pipeline/tiles.h"

namespace nmbake {

// Where the trace writes, allocated by the caller: the map (covered texels only), the coverage,
// the miss mask (when options.miss_mask) and, with several samples, per texel whether its samples
// disagree (suspect, kSuspectAgreement); empty: not wanted.
struct TraceTargets {
  Image& map;
  std::vector<std::uint8_t>& coverage;
  Image& miss_mask;
  std::vector<std::uint8_t>& disagree;
  // The extra maps (texel_maps.h): what they read (its groups set here) and where they go; null: none.
  MapInputs* map_inputs = nullptr;
  MapTargets* maps = nullptr;
};

// Traces every tile of `bins`, applying the hit rule of `scene` unless st.distances.backfaces_skipped is
// false. Fills in `st.trace`: rays, hits, misses, samples_covered, overlapping_samples, backface_skips,
// hits_facing_away, hit_distance_*, texels_total, texels_covered, coverage.
// Calls options.progress from the calling thread; throws Cancelled when it returns false.
void trace_and_shade(const Prepared& s, const HighScene& scene, const TileBins& bins, const RaySetup& rays,
                     const BakeOptions& opt, int threads, const TraceTargets& out, BakeStats& st);

// The texels `texels` (indices y * width + x, each once) of `bins` traced as trace_and_shade traces
// them, by the same tracer, with the samples of opt.samples (sample_offsets; opt.adaptive false);
// `st` as for trace_and_shade (its hit rule). Per texel, the renormalized mean of its samples (tangent space with
// --green down applied, or object space) as n in [-1,1]^3, not encoded and not snapped to 0, or
// (0,0,0) when the layout covers none of its samples. No progress is reported.
std::vector<glm::dvec3> trace_texels(const Prepared& s, const HighScene& scene, const TileBins& bins, const RaySetup& rays,
                                     const BakeOptions& opt, int threads, const BakeStats& st,
                                     const std::vector<std::uint32_t>& texels);

}  // namespace nmbake
