// The tangent-space normal codec, written once.
//
// Every step is a template over the number type T: double for one sample at a time
// (tangent_frames.h, pipeline/rays.cpp, nmdiff, the tests) and a vector of four doubles for the
// SIMD kernels (trace/shade_batch.cpp, trace/tile_kernels.cpp), so both run the same operations in
// the same order and give the same bits (tests/test_shade_batch.cpp and test_tile_kernels.cpp
// check it). The helpers take and give results by reference and are always inlined: a 32-byte
// vector passed by value would change the calling convention between the AVX2 and baseline clones.
//
// The convention (MikkTSpace, ../shared/docs/baking.md): N and T are interpolated across the
// triangle without normalizing, B = sign * cross(N, T) per pixel, and a map value t decodes to the
// world normal normalize(t.x * T + t.y * B + t.z * N). The map stores c = t * 0.5 + 0.5 per channel.
#pragma once

#include <cfloat>
#include <cmath>

namespace nmbake::codec {

// What the steps need beyond + - * /, per number type: the square root, and the comparisons
// (a bool for one sample, a lane mask for vectors: lanes.h gives the four- and eight-lane ones).
template <typename T>
struct Ops;
template <>
struct Ops<double> {
  static void root(double& r, const double& a) { r = std::sqrt(a); }
  static bool gt(double a, double b) { return a > b; }
  static bool ge(double a, double b) { return a >= b; }
  static bool lt(double a, double b) { return a < b; }
  static bool le(double a, double b) { return a <= b; }
  static bool invert(bool m) { return !m; }
};

template <typename T>
struct Vec3 {
  T x, y, z;
};

// glm::cross and glm::dot, term for term ((x + y) + z of the products).
template <typename T>
[[gnu::always_inline]] inline void cross(Vec3<T>& r, const Vec3<T>& a, const Vec3<T>& b) {
  r.x = a.y * b.z - b.y * a.z;
  r.y = a.z * b.x - b.z * a.x;
  r.z = a.x * b.y - b.x * a.y;
}
template <typename T>
[[gnu::always_inline]] inline void dot(T& r, const Vec3<T>& a, const Vec3<T>& b) {
  r = a.x * b.x + a.y * b.y + a.z * b.z;
}

// r = sum over corners c of w[c] * v[c], summed from zero in corner order.
template <typename T>
[[gnu::always_inline]] inline void interpolate(Vec3<T>& r, const T w[3], const Vec3<T> v[3], const T& zero) {
  r = {zero, zero, zero};
  for (int c = 0; c < 3; ++c) {
    r.x += w[c] * v[c].x;
    r.y += w[c] * v[c].y;
    r.z += w[c] * v[c].z;
  }
}

template <typename T>
struct Frame {
  Vec3<T> t, b, n;  // not orthonormal in general
};

// The per-pixel frame at barycentrics `bary` from the corners' normals, tangents and tangent signs
// (tangent.w): N and T interpolated, sign interpolated like them, B = sign * cross(N, T).
template <typename T>
[[gnu::always_inline]] inline void per_pixel_frame(Frame<T>& f, const T bary[3], const Vec3<T> normal[3],
                                                   const Vec3<T> tangent[3], const T sign_w[3], const T& zero) {
  interpolate(f.n, bary, normal, zero);
  interpolate(f.t, bary, tangent, zero);
  T sign = zero;
  for (int c = 0; c < 3; ++c) sign += bary[c] * sign_w[c];
  Vec3<T> nt;
  cross(nt, f.n, f.t);
  f.b = {sign * nt.x, sign * nt.y, sign * nt.z};
}

// The encoding of the world direction `world` (any positive length) in frame f, before its last
// step: the inverse of [T B N] applied by Cramer's rule as the adjugate times `world` (x), defined
// up to a positive scale because the decoding normalizes, so only the determinant's sign and zero
// matter; and what decides whether the result can be trusted: the frame is singular when
// det^2 <= 1e-24 |T|^2 |B|^2 |N|^2 (scale2), and x must have a finite, positive length (len).
template <typename T>
struct Encoding {
  Vec3<T> x;
  T det, scale2, len, inv;  // inv = 1 / len
};
template <typename T>
[[gnu::always_inline]] inline void encode_in_frame(Encoding<T>& e, const Frame<T>& f, const Vec3<T>& world) {
  Vec3<T> bxn, nxt, txb;
  cross(bxn, f.b, f.n);
  cross(nxt, f.n, f.t);
  cross(txb, f.t, f.b);
  dot(e.det, f.t, bxn);
  T tt, bb, nn;
  dot(tt, f.t, f.t);
  dot(bb, f.b, f.b);
  dot(nn, f.n, f.n);
  e.scale2 = tt * bb * nn;
  dot(e.x.x, world, bxn);
  dot(e.x.y, world, nxt);
  dot(e.x.z, world, txb);
  T xx;
  dot(xx, e.x, e.x);
  Ops<T>::root(e.len, xx);
  e.inv = 1.0 / e.len;
}
// The squared-determinant test of a singular frame.
constexpr double kSingular = 1e-24;
// Whether an encoding can be trusted: the frame not singular, det and len finite (NaN fails every
// comparison, and an infinity is beyond DBL_MAX), len positive. A bool for one sample, a lane
// mask for four.
template <typename T, typename Mask>
[[gnu::always_inline]] inline void trusted(Mask& r, const Encoding<T>& e) {
  const T zero{};
  r = Ops<T>::gt(e.det * e.det, kSingular * e.scale2) & Ops<T>::ge(e.det, zero - DBL_MAX) & Ops<T>::le(e.det, zero + DBL_MAX) &
      Ops<T>::gt(e.len, zero) & Ops<T>::le(e.len, zero + DBL_MAX);
}

// The encoded tangent-space unit vector, given the factor x is scaled by: inv where det > 0, -inv
// elsewhere (the caller picks it: a branch for one sample, a sign-bit mask for four).
template <typename T>
[[gnu::always_inline]] inline void scaled(Vec3<T>& r, const Vec3<T>& x, const T& factor) {
  r = {x.x * factor, x.y * factor, x.z * factor};
}

// One channel of a unit vector as stored in a map: c = n * 0.5 + 0.5.
template <typename T>
[[gnu::always_inline]] inline void to_channel(T& c, const T& n) {
  c = n * 0.5 + 0.5;
}
// A map's channel back to the component: 2c - 1 (before normalizing).
[[gnu::always_inline]] inline double from_channel(float c) { return 2.0 * double(c) - 1.0; }

// Shorter than this, a decoded texel has no direction (an encoded (0.5, 0.5, 0.5) is exactly 0).
constexpr double kShortestDecoded = 1e-6;

// A map texel (3 channels) decoded to a unit vector in n; false (n untouched) when its length is
// below kShortestDecoded or not finite.
inline bool decode_texel(const float* rgb, double n[3]) {
  const double v[3] = {from_channel(rgb[0]), from_channel(rgb[1]), from_channel(rgb[2])};
  const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(len) || len < kShortestDecoded) return false;
  for (int k = 0; k < 3; ++k) n[k] = v[k] / len;
  return true;
}

}  // namespace nmbake::codec
