// The trace's counters (pipeline/trace.h): one set per thread, summed into BakeStats at the end.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "pipeline/bake.h"

namespace nmbake {

// One cache line each: the counters change per sample, and shared lines would serialize threads.
struct alignas(64) ThreadStats {
  std::uint64_t rays = 0, hits = 0, misses = 0, covered = 0, overlaps = 0, backface_skips = 0, facing_away = 0, unmatched = 0;
  std::uint64_t base_texels = 0, refined_texels = 0, deep_texels = 0;  // adaptive (BakeStats::Trace::texels_base, ...)
  double dmin = std::numeric_limits<double>::infinity(), dmax = -std::numeric_limits<double>::infinity();
  // Per object, with several (BakeStats::Trace::low_object_samples, ...).
  std::vector<std::uint64_t> low_samples, low_hits, high_hits;
};

// Sums the threads' counters into `st`: rays, hits, misses, samples_covered, overlapping_samples,
// backface_skips, hits_facing_away, samples_unmatched, texels_base/refined/deep, the per-object
// counts (`low_objects` and `high_objects` long; with `per_object` false, one object each: the
// totals) and hit_distance_*, the mean from the tiles' sums of hit distances added in tile order (so
// it does not depend on which thread took which tile).
void sum_thread_stats(const std::vector<ThreadStats>& stats, bool per_object, std::size_t low_objects, std::size_t high_objects,
                      const std::vector<double>& tile_dsum, BakeStats& st);

}  // namespace nmbake
