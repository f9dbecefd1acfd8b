#include "core/cull.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/image.h"
#include "core/parallel.h"

namespace nmbake {

std::vector<std::uint32_t> triangles_near(const std::vector<Box>& regions, double margin, const std::vector<glm::vec3>& positions,
                                          const std::vector<std::uint32_t>& indices, const std::vector<std::uint32_t>* candidates,
                                          int threads, std::size_t list_below, bool* not_listed) {
  if (not_listed) *not_listed = false;
  const std::size_t tris = indices.size() / 3;
  std::vector<std::uint32_t> kept;
  if (regions.empty()) return kept;
  // Grown regions and their union.
  std::vector<Box> grown(regions.size());
  Box all{glm::dvec3(std::numeric_limits<double>::max()), glm::dvec3(-std::numeric_limits<double>::max())};
  glm::dvec3 mean_extent(0.0);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    grown[i] = {regions[i].lo - margin, regions[i].hi + margin};
    all.lo = glm::min(all.lo, grown[i].lo);
    all.hi = glm::max(all.hi, grown[i].hi);
    mean_extent += grown[i].hi - grown[i].lo;
  }
  mean_extent /= double(regions.size());
  // A grid over the union with about 8 cells per region, but cells no smaller than half a mean
  // region, so that marking touches a bounded number of cells per region.
  const glm::dvec3 extent = glm::max(all.hi - all.lo, glm::dvec3(1e-30));
  const double target_cells = std::clamp(8.0 * double(regions.size()), 4096.0, double(1 << 22));
  double h = std::cbrt(extent.x * extent.y * extent.z / target_cells);
  h = std::max({h, 0.5 * std::max({mean_extent.x, mean_extent.y, mean_extent.z}), 1e-30});
  int dim[3];
  for (int a = 0; a < 3; ++a) dim[a] = int(std::clamp(std::ceil(extent[a] / h), 1.0, 512.0));
  const glm::dvec3 inv(dim[0] / extent.x, dim[1] / extent.y, dim[2] / extent.z);
  auto cell_range = [&](const glm::dvec3& lo, const glm::dvec3& hi, int c0[3], int c1[3]) {
    for (int a = 0; a < 3; ++a) {
      c0[a] = int(std::clamp(std::floor((lo[a] - all.lo[a]) * inv[a]), 0.0, double(dim[a] - 1)));
      c1[a] = int(std::clamp(std::floor((hi[a] - all.lo[a]) * inv[a]), 0.0, double(dim[a] - 1)));
    }
  };
  std::vector<std::uint8_t> marked(std::size_t(dim[0]) * dim[1] * dim[2], 0);
  for (const Box& b : grown) {
    int c0[3], c1[3];
    cell_range(b.lo, b.hi, c0, c1);
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x) marked[(std::size_t(z) * dim[1] + y) * dim[0] + x] = 1;
  }
  // Per vertex, once: its cell on each axis, or that it lies beyond one side of the union. A
  // triangle's box is then its corners' cells' range (the cell of a coordinate never decreases
  // as it grows, so the cell of the smallest is the smallest cell), and it misses the union on an
  // axis where all three corners lie beyond one side: the answers of the box itself, bit for bit.
  // 10 bits per axis: 0 beyond the low side (whose cell is 0), 1 + the cell, or dim + 1 beyond the
  // high side (whose cell is dim - 1: the union's far side is dim cells from its near one).
  // Written whole on every thread: not zeroed on one thread first.
  std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>> vertex_cells(positions.size());
  parallel_chunks(threads, positions.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const glm::dvec3 p(positions[i]);
      int c0[3], c1[3];
      cell_range(p, p, c0, c1);
      std::uint32_t code = 0;
      for (int k = 0; k < 3; ++k) {
        // NaN-free inputs are the loader's promise.
        const int v = !(p[k] >= all.lo[k]) ? 0 : !(p[k] <= all.hi[k]) ? dim[k] + 1 : c0[k] + 1;
        code |= std::uint32_t(v) << (10 * k);
      }
      vertex_cells[i] = code;
    }
  });
  auto near = [&](std::size_t t) {
    const std::uint32_t corner[3] = {vertex_cells[indices[3 * t]], vertex_cells[indices[3 * t + 1]],
                                     vertex_cells[indices[3 * t + 2]]};
    int c0[3], c1[3];
    for (int k = 0; k < 3; ++k) {
      int lo = 1 << 10, hi = -1;
      for (std::uint32_t c : corner) {
        const int v = int(c >> (10 * k) & 1023u);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi == 0 || lo == dim[k] + 1) return false;  // all three beyond one side: outside the union
      c0[k] = std::clamp(lo - 1, 0, dim[k] - 1);
      c1[k] = std::clamp(hi - 1, 0, dim[k] - 1);
    }
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x)
          if (marked[(std::size_t(z) * dim[1] + y) * dim[0] + x]) return true;
    return false;
  };
  // In chunks on the threads: per triangle whether it is near (a byte), per chunk how many; then,
  // if they are to be listed, each chunk lists its own from where the chunks before it end: the
  // answer does not depend on the threads. (Lists grown per chunk, as before, took four times the
  // memory in small blocks, each page of them a fault.)
  const std::size_t count = candidates ? candidates->size() : tris;
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> is_near(count);  // written whole below
  std::vector<std::size_t> at(chunks + 1, 0);
  const auto triangle = [&](std::size_t i) { return candidates ? (*candidates)[i] : std::uint32_t(i); };
  parallel_chunks(threads, count, kChunk, [&](std::size_t begin, std::size_t end) {
    std::size_t n = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const bool k = near(triangle(i));
      is_near[i] = k;
      n += k;
    }
    at[begin / kChunk + 1] = n;
  });
  for (std::size_t c = 0; c < chunks; ++c) at[c + 1] += at[c];
  if (at.back() >= list_below) {  // the caller does not want so many listed
    if (not_listed) *not_listed = true;
    return kept;
  }
  kept.resize(at.back());
  parallel_chunks(threads, count, kChunk, [&](std::size_t begin, std::size_t end) {
    std::size_t to = at[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i)
      if (is_near[i]) kept[to++] = triangle(i);
  });
  return kept;
}

}  // namespace nmbake
