// Which texels nmdiff compares and what it keeps of them, shared by the normal-map comparison
// (nmdiff.h) and the other maps' (map_diff.h): a texel is compared when the mask (the low-poly's UV
// layout) and both maps' alpha coverage take it, or whatever they say with include_padding; the
// running tally of the compared texels' differences and the nearest-rank percentile both report.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace nmbake::diff {

enum class TexelSelection : std::uint8_t {
  outside_mask,   // not compared: the mask leaves it out
  outside_alpha,  // not compared: alpha < 0.5 in A or B
  compared,       // inside the mask and both alphas
  padding,        // compared only because of include_padding
};

// Texel `i` of A and B (same size; `mask` empty or one byte per texel, nonzero = compare). Alpha is
// the last of 2 or 4+ channels (none in 1 or 3); `use_alpha` false ignores it.
TexelSelection select_texel(const Image& a, const Image& b, std::size_t i, const std::vector<std::uint8_t>& mask, bool use_alpha,
                            bool include_padding);

// Counts a skipped texel in the stats' skipped_mask or skipped_alpha (DiffStats, MapDiffStats);
// true when the texel is skipped.
template <typename Stats>
bool count_skipped(TexelSelection t, Stats& s) {
  if (t == TexelSelection::outside_mask) ++s.skipped_mask;
  else if (t == TexelSelection::outside_alpha) ++s.skipped_alpha;
  else return false;
  return true;
}

// The compared texels' differences as they come: every value (for the percentiles), their sum and
// sum of squares, the largest and the first texel (row-major) holding it (-1: none yet).
struct DiffTally {
  std::vector<float> values;
  double sum = 0.0, sum_sq = 0.0, max = 0.0;
  int worst_x = -1, worst_y = -1;
  // Texel `i` of a map `width` texels wide differs by `d` (>= 0, in the comparison's units).
  void add(std::size_t i, int width, double d);

  // Mean, root mean square and the 95th and 99th nearest-rank percentiles of the values (values
  // reordered); all 0 when there are none.
  struct Summary {
    double mean = 0.0, rms = 0.0, p95 = 0.0, p99 = 0.0;
  };
  Summary summary();
};

// Nearest-rank percentile (p in [0, 1]) of unsorted values, reordered in place; 0 when empty.
double percentile(std::vector<float>& values, double p);

}  // namespace nmbake::diff
