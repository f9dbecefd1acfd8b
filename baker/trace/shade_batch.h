// The bake's shading step for many samples at once: the high-poly normal at each hit, encoded in
// the low-poly's per-pixel tangent frame.
//
// It computes, lane by lane, exactly the operations of interpolate_frame (per-pixel bitangent),
// the hit-normal interpolation and encode_tangent_normal, in the same order, so every result is
// bit-identical to the one-sample-at-a-time code; only the instruction count changes (4 samples
// per vector operation). Samples whose hit normal or frame is degenerate are not computed here:
// they are flagged for the caller's one-at-a-time path, which has the fallbacks.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace nmbake {

// What the trace loop reads of one low-poly triangle: re-centred corner positions, ray normals,
// and the tangent frame's corner normals and tangents, widened to double once (exact).
struct LowTriangle {
  glm::dvec3 p[3], ray_n[3], n[3];
  glm::dvec4 t[3];
};

// Samples to shade, as arrays: per sample, the low-poly triangle and barycentrics, and the hit's
// high-poly triangle (raycast's no_hit, 0xffffffff, for a miss) with its barycentrics u, v of
// corners 1 and 2 (Embree's convention).
struct ShadeSamples {
  const std::int32_t* low_tri;
  const double* b[3];
  const std::uint32_t* high_tri;
  const float* u;
  const float* v;
};

// A hit normal (interpolated, before normalizing) whose squared length is at most this is too
// short to encode as it is: the one-at-a-time path takes its fallbacks.
constexpr double kShortHitNormal2 = 1e-24;

// For i < count: value[c][i] = component c of encode_tangent_normal(interpolate_frame(low[low_tri],
// b, per_pixel), interpolated high-poly normal), and degenerate[i] = 0; or degenerate[i] = 1
// (value unspecified) for a miss, or when the interpolated hit normal's squared length is at most
// kShortHitNormal2, the frame singular or the result not finite. high_corner_normals holds 3 normals per
// high-poly triangle.
void encode_hits_per_pixel(const LowTriangle* low, const glm::vec3* high_corner_normals, const ShadeSamples& samples,
                           std::size_t count, double* const value[3], std::uint8_t* degenerate);

}  // namespace nmbake
