// nmview --compare's verdict on a bake, run as a user would (the real nmbake and nmview, headless):
// shared by the verdict tests of the bundled sample and of the shared sculpts.
#pragma once

#include <string>

namespace nmview::test {

// The last stdout line's verdict and figures (degrees; removes a share).
struct VerdictRun {
  std::string verdict;
  double removes = 0.0, with_map = 0.0, no_map = 0.0;
};

// nmview LOW MAP HIGH --compare --size `size`, in `dir`; its exit status is expected 0.
VerdictRun compare_verdict(const std::string& dir, const std::string& low, const std::string& map, const std::string& high,
                           const std::string& size = "300x150");

// Bakes LOW from HIGH at `map_size`^2 with the real nmbake, then expects --compare's verdict good
// for that map (removing at least kMinRemoved + 0.05 of the no-map angle), green_flipped for the same
// pixels with green flipped (no metadata: decoded green up, as baked), and barely_helps for a flat
// map (its angle the no-map one). `size` is nmview's --size.
void expect_verdicts(const std::string& low, const std::string& high, int map_size, const std::string& size = "300x150");

}  // namespace nmview::test
