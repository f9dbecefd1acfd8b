// Stage 3 of the bake, select: the high-poly triangles some ray can reach (far-geometry culling,
// core/cull.h). Rays stay within a margin of their low-poly triangle's box, grown over its cage
// triangle when there is one; the margin is how far they reach.
#pragma once

#include <cstdint>
#include <vector>

#include "core/cull.h"
#include "core/mesh.h"
#include "pipeline/prepare.h"

namespace nmbake {

// Per low-poly triangle, its box, grown over its cage triangle when there is one.
std::vector<Box> low_regions(const Prepared& s);

// The margin around a low-poly triangle's box that rays reaching `front` out and `rear` in stay
// within (from a cage: its triangle's box and `rear`), with slack for float rays.
double ray_margin(const Prepared& s, bool cage, double front, double rear);

// The high-poly triangles within `margin` of some region, increasing; empty when that is all of
// them.
std::vector<std::uint32_t> select_reachable(const Prepared& s, const Mesh& high, double margin);

// Of the triangles `kept` (empty: all), those within `margin` of some region, increasing, when they
// leave out a fifth of them or more (a rebuild then pays); else `kept` unchanged. Returns whether
// `kept` changed.
bool narrow_reachable(const Prepared& s, const Mesh& high, double margin, std::vector<std::uint32_t>& kept);

}  // namespace nmbake
