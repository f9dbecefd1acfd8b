// How deep a mesh's UV layout lies on itself: the share of covered texels that more than one UV
// triangle covers, and how many layers cover them.
//
// Stacked mirrored halves (two layers over part of the map) are a common and legal layout; UVs
// laid out for a tiling texture, or each face mapped onto the whole square, stack tens or hundreds
// of layers and give a map of confetti. The bake takes the lowest triangle index where islands
// overlap (rasterize.h); this measure lets the command say how much of the map that decided.
#pragma once

#include <cstdint>

#include "core/mesh.h"

namespace nmbake {

struct UvOverlap {
  int width = 0, height = 0;     // the texel grid measured (texel centres, rasterize.h's convention)
  std::uint64_t covered = 0;     // texel centres covered by at least one UV triangle
  std::uint64_t overlapped = 0;  // ... by two or more
  std::uint64_t stacked = 0;     // ... by three or more
  std::uint64_t layers = 0;      // covering triangles summed over the covered centres (>= covered)

  double overlapped_share() const { return covered ? double(overlapped) / double(covered) : 0.0; }
  double stacked_share() const { return covered ? double(stacked) / double(covered) : 0.0; }
  // The mean number of triangles over a covered texel: 1 without overlap, ~2 for stacked mirrored
  // halves, the number of repeats for tiled UVs.
  double mean_layers() const { return covered ? double(layers) / double(covered) : 0.0; }
};

// Counts the triangles over each texel centre of a width x height grid. Without `udim`, the unit
// square only (UVs are not wrapped); with it, each triangle in the UDIM tile of its UV centroid (u in
// [0,10), v >= 0; others are left out) and only triangles of one tile count as overlapping. Runs on
// `threads` threads (0: all cores); the counts do not depend on them.
UvOverlap measure_uv_overlap(const Mesh& mesh, int width, int height, bool udim, int threads = 0);

}  // namespace nmbake
