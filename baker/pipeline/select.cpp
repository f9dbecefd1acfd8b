#include "pipeline/select.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/image.h"
#include "core/parallel.h"

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

std::vector<std::uint32_t> select_reachable(const Prepared& s, const Mesh& high, double margin, int threads) {
  // Every triangle near: empty, all (not listed).
  return triangles_near(low_regions(s), margin, s.high_pos, high.position_index, nullptr, threads, high.triangle_count());
}

bool narrow_reachable(const Prepared& s, const Mesh& high, double margin, std::vector<std::uint32_t>& kept, int threads) {
  // Empty: all (no list of every triangle, which would add to the bake's peak memory). Narrowed
  // only below 0.8 of the current count (fewer than its ceiling, as counts are whole): a longer
  // list is not made.
  const std::size_t current = kept.empty() ? high.triangle_count() : kept.size();
  bool not_listed = false;
  std::vector<std::uint32_t> nearer =
      triangles_near(low_regions(s), margin, s.high_pos, high.position_index, kept.empty() ? nullptr : &kept, threads,
                     std::size_t(std::ceil(0.8 * double(current))), &not_listed);
  if (not_listed || !(double(nearer.size()) < 0.8 * double(current))) return false;
  kept = std::move(nearer);
  return true;
}

HighSelection select_high(const Prepared& s, const Mesh& high, double margin, int threads) {
  HighSelection sel;
  if (margin >= 0.0) sel.kept = select_reachable(s, high, margin, threads);
  sel.duplicates_skipped = drop_duplicate_floods(s, high, threads, sel.kept);
  return sel;
}

bool narrow_high(const Prepared& s, const Mesh& high, bool cage, double front, double rear,
                 const std::vector<float>& vertex_search, HighSelection& sel, int threads) {
  double reach_out = 0.0;
  for (float d : vertex_search) reach_out = std::max(reach_out, double(d));
  return narrow_reachable(s, high, ray_margin(s, cage, front, std::max(rear, reach_out)), sel.kept, threads);
}

namespace {

// A triangle's corner positions as bits, rotated to start at the smallest (winding kept).
using TriangleKey = std::array<std::uint32_t, 9>;

TriangleKey triangle_key(const Prepared& s, const Mesh& high, std::uint32_t t) {
  std::array<std::array<std::uint32_t, 3>, 3> c;
  for (int k = 0; k < 3; ++k) std::memcpy(c[k].data(), &s.high_pos[high.position_index[3 * std::size_t(t) + k]], 12);
  const int first = int(std::min_element(c.begin(), c.end()) - c.begin());
  TriangleKey key;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) key[3 * k + j] = c[(first + k) % 3][j];
  return key;
}

std::uint64_t key_hash(const TriangleKey& key) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint32_t b : key) h = (h ^ b) * 1099511628211ull;
  return h ^ (h >> 31);
}

}  // namespace

std::size_t drop_duplicate_floods(const Prepared& s, const Mesh& high, int threads, std::vector<std::uint32_t>& kept) {
  const std::size_t n = kept.empty() ? high.triangle_count() : kept.size();
  auto triangle = [&](std::size_t i) { return kept.empty() ? std::uint32_t(i) : kept[i]; };
  // Count triangles per hash bucket: a group of k identical triangles puts k in one bucket.
  std::size_t buckets = 1024;
  while (buckets < 2 * n) buckets *= 2;
  // Both written whole on every thread before they are read: not zeroed on one thread first.
  std::vector<std::uint16_t, DefaultInitAllocator<std::uint16_t>> count(buckets);
  std::vector<std::uint64_t, DefaultInitAllocator<std::uint64_t>> hash(n);
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  fill_on_threads(threads, count, std::uint16_t(0));
  parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) hash[i] = key_hash(triangle_key(s, high, triangle(i)));
  });
  // Counted on every core, each count raised by compare-and-swap up to its limit: the counts, and
  // whether one passes kDuplicateFlood, do not depend on the order of the increments.
  std::atomic<bool> suspects{false};
  parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
    bool seen = false;
    constexpr std::size_t kAhead = 16;  // the counts are larger than the caches: fetch ahead
    for (std::size_t i = begin; i < end; ++i) {
      if (i + kAhead < end) __builtin_prefetch(&count[hash[i + kAhead] & (buckets - 1)], 1);
      std::uint16_t* c = &count[hash[i] & (buckets - 1)];
      std::uint16_t was = __atomic_load_n(c, __ATOMIC_RELAXED);
      while (was < UINT16_MAX &&
             !__atomic_compare_exchange_n(c, &was, std::uint16_t(was + 1), true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
      }
      seen |= std::size_t(was < UINT16_MAX ? was + 1 : was) > kDuplicateFlood;
    }
    if (seen) suspects = true;
  });
  if (!suspects) return 0;
  // The triangles of crowded buckets, grouped by key (first triangle first); repeats are left out.
  struct Suspect {
    TriangleKey key;
    std::uint32_t triangle;
  };
  std::vector<Suspect> crowded;
  for (std::size_t i = 0; i < n; ++i)
    if (count[hash[i] & (buckets - 1)] > kDuplicateFlood) crowded.push_back({triangle_key(s, high, triangle(i)), triangle(i)});
  std::sort(crowded.begin(), crowded.end(),
            [](const Suspect& a, const Suspect& b) { return a.key != b.key ? a.key < b.key : a.triangle < b.triangle; });
  std::vector<std::uint32_t> dropped;
  for (std::size_t i = 0; i < crowded.size();) {
    std::size_t j = i + 1;
    while (j < crowded.size() && crowded[j].key == crowded[i].key) ++j;
    if (j - i > kDuplicateFlood)
      for (std::size_t k = i + 1; k < j; ++k) dropped.push_back(crowded[k].triangle);
    i = j;
  }
  if (dropped.empty()) return 0;
  std::sort(dropped.begin(), dropped.end());
  std::vector<std::uint32_t> result;
  result.reserve(n - dropped.size());
  for (std::size_t i = 0; i < n; ++i)
    if (!std::binary_search(dropped.begin(), dropped.end(), triangle(i))) result.push_back(triangle(i));
  kept = std::move(result);
  return dropped.size();
}

}  // namespace nmbake
