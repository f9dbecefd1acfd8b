#include "pipeline/select.h"

#include <algorithm>

namespace nmbake {

std::vector<Box> low_regions(const Prepared& s) {
  std::vector<Box> regions(s.low_tris.size());
  for (std::size_t t = 0; t < regions.size(); ++t) {
    Box b{s.low_tris[t].p[0], s.low_tris[t].p[0]};
    for (int c = 0; c < 3; ++c) {
      b.lo = glm::min(b.lo, s.low_tris[t].p[c]);
      b.hi = glm::max(b.hi, s.low_tris[t].p[c]);
      if (!s.cage_tris.empty()) {
        b.lo = glm::min(b.lo, s.cage_tris[t].corner[c]);
        b.hi = glm::max(b.hi, s.cage_tris[t].corner[c]);
      }
    }
    regions[t] = b;
  }
  return regions;
}

double ray_margin(const Prepared& s, bool cage, double front, double rear) {
  // Rays are cast in float: a little slack keeps the test conservative.
  return 1.01 * (cage ? rear : std::max(front, rear)) + 1e-6 * s.diagonal;
}

std::vector<std::uint32_t> select_reachable(const Prepared& s, const Mesh& high, double margin) {
  std::vector<std::uint32_t> kept = triangles_near(low_regions(s), margin, s.high_pos, high.position_index);
  if (kept.size() == high.triangle_count()) kept.clear();
  return kept;
}

bool narrow_reachable(const Prepared& s, const Mesh& high, double margin, std::vector<std::uint32_t>& kept) {
  std::vector<std::uint32_t> all;
  if (kept.empty()) {
    all.resize(high.triangle_count());
    for (std::size_t t = 0; t < all.size(); ++t) all[t] = std::uint32_t(t);
  }
  const std::vector<std::uint32_t>& current = kept.empty() ? all : kept;
  std::vector<std::uint32_t> nearer = triangles_near(low_regions(s), margin, s.high_pos, high.position_index, &current);
  if (!(double(nearer.size()) < 0.8 * double(current.size()))) return false;
  kept = std::move(nearer);
  return true;
}

}  // namespace nmbake
