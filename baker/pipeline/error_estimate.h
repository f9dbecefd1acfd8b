// Error estimate of a finished bake: a random subset of its covered texels re-baked with many
// samples, and the angle between the bake's values and those.
//
// The re-bake traces the chosen texels through the bake's own tracer (trace_texels, trace.h) over
// the scene, BVH and rays the bake kept (BakeOptions::keep_trace), so what it measures is the
// sampling error of the bake's --samples at its --size (aliasing of detail finer than a texel), not
// the high-poly's own tessellation. Angles are between the tangent-space (or object-space) unit
// vectors of the float map (BakeResult::map, before any quantisation), in degrees. The output's bit
// depth adds quantisation on top; `quantization_*` measures it on the same texels.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/bake.h"

namespace nmbake {

struct UvTileFilter;  // tiles.h
struct TraceInputs;   // bake_stages.h

struct ErrorEstimateOptions {
  std::size_t texels = 4096;   // covered texels re-baked (all of them when fewer are covered)
  int samples = 64;            // samples per re-baked texel; at least 4x the bake's, at most kMaxSamples
  std::uint64_t seed = 12111;  // texel choice (fixed: the same bake gives the same estimate)
  int bits = 32;               // output bit depth: 8, 16, or 32 (float, no quantisation)
  // A UDIM tile's map (udim.h): its triangles alone, their UVs moved into 0-1; null: the map of the
  // whole layout.
  const UvTileFilter* tile = nullptr;
};

struct ErrorEstimate {
  double mean_deg = 0, p95_deg = 0, max_deg = 0;  // bake against the re-bake, over `texels`
  std::size_t texels = 0;                         // texels compared
  int samples = 0;                                // samples per texel of the re-bake
  double seconds = 0;                             // wall time of the estimate
  // Angle between the float map and its values rounded to `bits` (0 for float output).
  double quantization_mean_deg = 0, quantization_max_deg = 0;
};

// `result` must come from bake_normal_map(low, high, cage, options) with options.keep_trace (its
// trace_inputs; std::invalid_argument otherwise).
ErrorEstimate estimate_bake_error(const Mesh& low, const BakeOptions& options, const BakeResult& result,
                                  const ErrorEstimateOptions& estimate = {});

// The same over the given trace inputs (a UDIM tile's map: UdimBake::trace_inputs, udim.h).
ErrorEstimate estimate_bake_error(const Mesh& low, const TraceInputs& traced, const BakeOptions& options,
                                  const BakeResult& result, const ErrorEstimateOptions& estimate = {});

}  // namespace nmbake
