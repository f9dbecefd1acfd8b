// The bake's shading step for many samples at once: the high-poly normal at each hit, encoded in
// the low-poly's per-pixel tangent frame.
//
// It computes, lane by lane, exactly the operations of interpolate_frame (per-pixel bitangent),
// the hit-normal interpolation and encode_tangent_normal, in the same order, so every result is
// bit-identical to the one-sample-at-a-time code; only the instruction count changes (4 samples
// per vector operation, 8 on an AVX-512 CPU). Samples whose hit normal or frame is degenerate are not computed here:
// they are flagged for the caller's one-at-a-time path, which has the fallbacks.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/codec.h"

namespace nmbake {

// What the trace loop reads of one low-poly triangle: re-centred corner positions, ray normals,
// and the tangent frame's corner normals and tangents, widened to double once (exact).
struct LowTriangle {
  glm::dvec3 p[3], ray_n[3], n[3];
  glm::dvec4 t[3];
};

// A low-poly triangle's cage: its corners (re-centred), and per corner the rear distance and how
// far out rays search (LocalDistances::search; 0: to the cage only).
struct CageTriangle {
  glm::dvec3 corner[3];
  double rear[3] = {0, 0, 0}, search[3] = {0, 0, 0};
};

// The default rays, written once over the number type (double for one sample in
// pipeline/rays.h, four lanes in trace/tile_kernels.cpp).
// r = w0 c0 + w1 c1 + w2 c2, summed left to right (as glm's b[0] * c[0] + b[1] * c[1] + b[2] * c[2]).
template <typename T>
[[gnu::always_inline]] inline void corner_sum(codec::Vec3<T>& r, const glm::dvec3 c[3], const T w[3]) {
  r = {w[0] * c[0].x, w[0] * c[0].y, w[0] * c[0].z};
  for (int k = 1; k < 3; ++k) r = {r.x + w[k] * c[k].x, r.y + w[k] * c[k].y, r.z + w[k] * c[k].z};
}
// At barycentrics w of triangle lt: P, and the ray normal N times 1 / |N|, with len2 = |N|^2 (at
// most 1e-24: N cannot be trusted, and the caller falls back to the face normal).
template <typename T>
[[gnu::always_inline]] inline void low_point_and_normal(codec::Vec3<T>& p, codec::Vec3<T>& n, T& len2, const LowTriangle& lt,
                                                        const T w[3]) {
  corner_sum(p, lt.p, w);
  corner_sum(n, lt.ray_n, w);
  codec::dot(len2, n, n);
  T len;
  codec::Ops<T>::root(len, len2);
  const T inv = 1.0 / len;
  n = {n.x * inv, n.y * inv, n.z * inv};
}
// The default policy's ray: from P + front N along -N.
template <typename T>
[[gnu::always_inline]] inline void default_ray(codec::Vec3<T>& org, codec::Vec3<T>& dir, const codec::Vec3<T>& p,
                                               const codec::Vec3<T>& n, double front) {
  org = {p.x + front * n.x, p.y + front * n.y, p.z + front * n.z};
  dir = {-n.x, -n.y, -n.z};
}

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
// `lanes`: 0 for the fastest version this CPU runs (8 lanes per instruction on an AVX-512 CPU, else
// 4), or 4 or 8 to ask for one (for tests; 8 only where kernel_lanes_available(8)).
void encode_hits_per_pixel(const LowTriangle* low, const glm::vec3* high_corner_normals, const ShadeSamples& samples,
                           std::size_t count, double* const value[3], std::uint8_t* degenerate, int lanes = 0);

// Whether the kernels' versions of `lanes` lanes (4 or 8) run on this CPU: 4 always, 8 on an
// AVX-512 (x86-64-v4) one.
bool kernel_lanes_available(int lanes);

}  // namespace nmbake
