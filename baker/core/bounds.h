// The bounding box of the points a mesh's faces use, on every core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.h"

namespace nmbake {

// An axis-aligned box, lo <= hi on each axis for a box that holds anything.
struct Box {
  glm::dvec3 lo{0.0}, hi{0.0};
  double diagonal() const { return glm::length(hi - lo); }
};

// Grows [lo, hi] by the points `index` refers to (a vertex no face uses, a stray point far away,
// does not count), in chunks on `threads` threads (0: all cores), each chunk's box joined to the
// others' after: smallest and largest values, so the same whatever the order. In double.
template <typename Point>
void grow_box(glm::dvec3& lo, glm::dvec3& hi, const std::vector<Point>& pts, const std::vector<std::uint32_t>& index,
              int threads = 0) {
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> boxes((index.size() + kChunk - 1) / kChunk, {lo, hi});
  parallel_chunks(threads, index.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    auto& [l, h] = boxes[begin / kChunk];
    for (std::size_t c = begin; c < end; ++c) {
      l = glm::min(l, glm::dvec3(pts[index[c]]));
      h = glm::max(h, glm::dvec3(pts[index[c]]));
    }
  });
  for (const auto& [l, h] : boxes) {
    lo = glm::min(lo, l);
    hi = glm::max(hi, h);
  }
}

}  // namespace nmbake
