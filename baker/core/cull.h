// Leaving out high-poly triangles no ray can reach.
//
// Every ray of a bake starts and ends within a known distance of its low-poly triangle (front and
// rear along the ray normal, or the cage triangle plus rear). A high-poly triangle whose bounding
// box is farther than that from every low-poly triangle's box can never be hit, so it need not be
// in the BVH. The test is conservative (boxes and grid cells, never exact distances): it may keep a
// triangle that cannot be hit, never drop one that can, so the map is the same with or without it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/bounds.h"

namespace nmbake {

// The high-poly triangles (index triples into `positions`) whose bounding box overlaps some box of
// `regions` grown by `margin` on every side, in increasing order. `candidates`, when not null,
// limits the answer to those triangles (themselves in increasing order). `threads` share the
// triangles (0: all cores); the answer does not depend on it. When `list_below` or more are near,
// they are not listed (a caller that would not keep so long a list): the answer is empty and
// *not_listed (when given) true.
std::vector<std::uint32_t> triangles_near(const std::vector<Box>& regions, double margin, const std::vector<glm::vec3>& positions,
                                          const std::vector<std::uint32_t>& indices,
                                          const std::vector<std::uint32_t>* candidates = nullptr, int threads = 0,
                                          std::size_t list_below = SIZE_MAX, bool* not_listed = nullptr);

}  // namespace nmbake
