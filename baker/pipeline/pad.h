// Stage 7 of the bake, pad: the background (never reached by padding) set to the flat normal, the
// suspect texels found, and the islands' edges padded (core/padding.h): the normal map's and those
// of result.maps (finish_maps, map_set.h: called before, so that the texture set is padded in the
// same pass).
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/bake.h"

namespace nmbake {

// `disagree`: per texel, whether its samples disagree (trace.h; empty with one sample). Fills in
// result.stats.pad: texels_facing_away, suspect_*, texels_padded; and result.suspect_mask when asked.
void pad_map(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, int threads, BakeResult& result);

}  // namespace nmbake
