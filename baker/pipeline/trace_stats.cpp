#include "pipeline/trace_stats.h"

#include <algorithm>

namespace nmbake {

namespace {

// BakeStats' per-object counts: summed over the threads, or with one object each the totals.
void count_per_object(const std::vector<ThreadStats>& stats, bool per_object, std::size_t low_objects, std::size_t high_objects,
                      BakeStats& st) {
  st.trace.low_object_samples.assign(low_objects, 0);
  st.trace.low_object_hits.assign(low_objects, 0);
  st.trace.high_object_hits.assign(high_objects, 0);
  if (!per_object) {
    st.trace.low_object_samples[0] = st.trace.samples_covered;
    st.trace.low_object_hits[0] = st.trace.high_object_hits[0] = st.trace.hits;
    return;
  }
  for (const ThreadStats& ts : stats) {
    for (std::size_t k = 0; k < ts.low_samples.size(); ++k) {
      st.trace.low_object_samples[k] += ts.low_samples[k];
      st.trace.low_object_hits[k] += ts.low_hits[k];
    }
    for (std::size_t k = 0; k < ts.high_hits.size(); ++k) st.trace.high_object_hits[k] += ts.high_hits[k];
  }
}

}  // namespace

void sum_thread_stats(const std::vector<ThreadStats>& stats, bool per_object, std::size_t low_objects, std::size_t high_objects,
                      const std::vector<double>& tile_dsum, BakeStats& st) {
  ThreadStats total;
  for (const ThreadStats& ts : stats) {
    total.rays += ts.rays;
    total.hits += ts.hits;
    total.misses += ts.misses;
    total.covered += ts.covered;
    total.overlaps += ts.overlaps;
    total.backface_skips += ts.backface_skips;
    total.facing_away += ts.facing_away;
    total.unmatched += ts.unmatched;
    total.base_texels += ts.base_texels;
    total.refined_texels += ts.refined_texels;
    total.deep_texels += ts.deep_texels;
    total.dmin = std::min(total.dmin, ts.dmin);
    total.dmax = std::max(total.dmax, ts.dmax);
  }
  st.trace.rays = total.rays;
  st.trace.hits = total.hits;
  st.trace.misses = total.misses;
  st.trace.samples_covered = total.covered;
  st.trace.overlapping_samples = total.overlaps;
  st.trace.backface_skips = total.backface_skips;
  st.trace.hits_facing_away = total.facing_away;
  st.trace.samples_unmatched = total.unmatched;
  st.trace.texels_base = total.base_texels;
  st.trace.texels_refined = total.refined_texels;
  st.trace.texels_deep = total.deep_texels;
  count_per_object(stats, per_object, low_objects, high_objects, st);
  if (total.hits) {
    st.trace.hit_distance_min = total.dmin;
    st.trace.hit_distance_max = total.dmax;
    double dsum = 0.0;
    for (double d : tile_dsum) dsum += d;
    st.trace.hit_distance_mean = dsum / double(total.hits);
  }
}

}  // namespace nmbake
