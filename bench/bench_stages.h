// The bake's stages (pipeline/bake_stages.h) composed for the bench: the rays a bake casts, for
// the bare Embree loops, and the trace stage cast texel by texel without the hit rule.
#pragma once

#include <vector>

#include "core/mesh.h"
#include "pipeline/bake.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"
#include "pipeline/tiles.h"
#include "raycast.h"

namespace nmbake::bench {

// The rays the trace stage casts over `bins` (the same values, bit for bit, in its order): tile by
// tile; within a tile texel by texel in rows, each texel's samples in sample order.
std::vector<raycast::Ray> tile_rays(const Prepared& s, const TileBins& bins, const RaySetup& setup,
                                    const std::vector<glm::dvec2>& offsets, int width, int height);

// The rays bake_normal_map casts with these options (not adaptive; no cage file), in coordinates
// re-centred on stats.centre, and the stats of the stages before the trace (distances, culling,
// BVH quality).
struct BakeRays {
  std::vector<raycast::Ray> rays;
  BakeStats stats;
};
BakeRays bake_rays(const Mesh& low, const Mesh& high, const BakeOptions& options);

// bake_normal_map's stages up to the trace, then its trace (texel by texel, with or without the
// hit rule, as the bake casts). The stats, seconds_trace and cpu_seconds_trace timed as the bake
// times them.
BakeStats trace_by_texel(const Mesh& low, const Mesh& high, const BakeOptions& options);

}  // namespace nmbake::bench
