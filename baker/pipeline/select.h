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
std::vector<std::uint32_t> select_reachable(const Prepared& s, const Mesh& high, double margin, int threads = 0);

// Of the triangles `kept` (empty: all), those within `margin` of some region, increasing, when they
// leave out a fifth of them or more (a rebuild then pays); else `kept` unchanged. Returns whether
// `kept` changed.
bool narrow_reachable(const Prepared& s, const Mesh& high, double margin, std::vector<std::uint32_t>& kept, int threads = 0);

// Groups of identical high-poly triangles (the same three corner positions, in the same winding)
// larger than this are kept once in the BVH.
constexpr std::size_t kDuplicateFlood = 8;

// Leaves out of `kept` (empty: all triangles) every triangle of a group of more than
// kDuplicateFlood identical ones but the first: a ray that meets such a stack met every triangle
// of it (and its hit filter ran for each), so a million copies of a face took minutes to bake.
// Found in O(n) for meshes without such groups (hashes on `threads` threads, then a count), and
// O(k log k) for k suspects: 12-17 ms for 0.4 million triangles on our 2-core VM. Returns
// the number left out.
std::size_t drop_duplicate_floods(const Prepared& s, const Mesh& high, int threads, std::vector<std::uint32_t>& kept);

}  // namespace nmbake
