// Adaptive sampling's levels (--samples auto, BakeOptions::adaptive), for the trace stage
// (trace.cpp): the first pass's points and the passes that refine the texels whose samples disagree.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "pipeline/bake.h"

namespace nmbake {

// The 2x2 Gauss-Legendre points of a texel, (1 -+ 1/sqrt(3)) / 2 on each axis: their equal-weight
// mean integrates a normal varying as a cubic across the texel exactly, where a stratified 4x4
// grid leaves an error of 1/384 of the second derivative times the texel size squared.
inline std::vector<glm::dvec2> gauss_legendre_offsets() {
  const double a = 0.5 - 0.5 / std::sqrt(3.0), b = 0.5 + 0.5 / std::sqrt(3.0);
  return {{a, a}, {b, a}, {a, b}, {b, b}};
}

// Adaptive sampling's passes after the first: the texels whose samples so far disagree are baked
// again with `offsets` (a square grid, so a texel then holds exactly a fixed bake's value with that
// many). A sample farther than the level's angle from its texel's mean refines the texel.
struct RefineLevel {
  std::vector<glm::dvec2> offsets;
  double cos_max = 1.0;
  bool partial = false;  // also the texels an island's edge cuts (fewer samples than offsets)
};

inline std::vector<RefineLevel> refine_levels(const BakeOptions& o) {
  if (!o.adaptive) return {};
  const double rad = o.max_error_deg * (3.14159265358979323846 / 180.0);
  std::vector<RefineLevel> levels{{sample_offsets(o.samples), std::cos(rad), true}};
  if (o.deep_factor > 0.0 && 4 * o.samples <= kMaxSamples)
    levels.push_back({sample_offsets(4 * o.samples), std::cos(std::min(o.deep_factor * rad, 1.5)), false});
  return levels;
}

}  // namespace nmbake
