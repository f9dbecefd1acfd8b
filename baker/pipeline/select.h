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

// The high-poly triangles a BVH holds.
struct HighSelection {
  std::vector<std::uint32_t> kept;     // increasing; empty: all
  std::size_t duplicates_skipped = 0;  // left out as repeats in stacks of identical triangles (drop_duplicate_floods)
  std::size_t count(const Mesh& high) const { return kept.empty() ? high.triangle_count() : kept.size(); }
};

// The select stage: the triangles within `margin` of some region (select_reachable), or all of
// them when `margin` < 0, less the repeats of duplicate floods.
HighSelection select_high(const Prepared& s, const Mesh& high, double margin, int threads);

// The narrow stage, once the distances are known: `sel` narrowed to the triangles rays reach
// (narrow_reachable with ray_margin), when that leaves out a fifth of them or more. Rays from a
// cage reach `rear` beyond P and, where they search beyond the cage, as far out as they search
// (`vertex_search`, per low-poly position). Returns whether `sel` changed (the BVH is then rebuilt).
bool narrow_high(const Prepared& s, const Mesh& high, bool cage, double front, double rear,
                 const std::vector<float>& vertex_search, HighSelection& sel, int threads);

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
// of it (and its hit filter ran for each).
// Found in O(n) for meshes without such groups (hashes on `threads` threads, then a count), and
// O(k log k) for k suspects. Returns the number left out.
std::size_t drop_duplicate_floods(const Prepared& s, const Mesh& high, int threads, std::vector<std::uint32_t>& kept);

}  // namespace nmbake
