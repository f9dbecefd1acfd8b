#include "trace/shade_batch.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "core/lanes.h"
#include "raycast.h"

namespace nmbake {

using namespace lanes;

namespace {

// L::n samples from `i` on (a short last block repeats its last sample). `same_triangle`: all on
// one low-poly triangle, whose data is then loaded once and broadcast instead of gathered.
template <typename L, bool same_triangle>
[[gnu::always_inline]] inline void encode_block(const LowTriangle* low, const glm::vec3* high_corner_normals,
                                                const ShadeSamples& in, std::size_t i, std::size_t count, double* const value[3],
                                                std::uint8_t* degenerate) {
  using V = typename L::V;
  using M = typename L::M;
  using F = typename L::F;
  using V3 = codec::Vec3<V>;
  constexpr int kN = L::n;
  const V zero = {};
  const bool full = i + kN <= count;
  std::size_t at[kN];
  for (int k = 0; k < kN; ++k) at[k] = std::min(i + std::size_t(k), count - 1);
  const LowTriangle* lp[kN];
  const glm::vec3* hp[kN];
  unsigned miss = 0;
#pragma GCC unroll 8
  for (int k = 0; k < kN; ++k) {
    lp[k] = &low[in.low_tri[same_triangle ? i : at[k]]];
    const std::uint32_t ht = in.high_tri[at[k]];
    miss |= unsigned(ht == raycast::no_hit) << k;
    hp[k] = &high_corner_normals[3 * std::size_t(ht == raycast::no_hit ? 0 : ht)];  // a miss reads any triangle, and is flagged
  }
  V b[3], tw[3];
  V3 n[3], t[3], hn[3];
  // One triangle's value in every lane (broadcast), or each lane's triangle's (gathered).
  const auto low_value = [&](V& r, auto field) {
    if constexpr (same_triangle) r = zero + field(lp[0]);
    else gather(r, [&](int k) { return field(lp[k]); });
  };
  // The hit normals' floats gathered, then widened to double at once (exact).
  const auto high_value = [&](V& r, auto field) {
    F f;
    for (int k = 0; k < kN; ++k) f[k] = field(hp[k]);
    r = __builtin_convertvector(f, V);
  };
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
    if (full) std::memcpy(&b[c], &in.b[c][i], sizeof(V));
    else gather(b[c], [&](int k) { return in.b[c][at[k]]; });
    low_value(n[c].x, [c](const LowTriangle* l) { return l->n[c].x; });
    low_value(n[c].y, [c](const LowTriangle* l) { return l->n[c].y; });
    low_value(n[c].z, [c](const LowTriangle* l) { return l->n[c].z; });
    low_value(t[c].x, [c](const LowTriangle* l) { return l->t[c].x; });
    low_value(t[c].y, [c](const LowTriangle* l) { return l->t[c].y; });
    low_value(t[c].z, [c](const LowTriangle* l) { return l->t[c].z; });
    low_value(tw[c], [c](const LowTriangle* l) { return l->t[c].w; });
    high_value(hn[c].x, [c](const glm::vec3* h) { return h[c].x; });
    high_value(hn[c].y, [c](const glm::vec3* h) { return h[c].y; });
    high_value(hn[c].z, [c](const glm::vec3* h) { return h[c].z; });
  }
  V u, v;
  if (full) {
    F uf, vf;
    std::memcpy(&uf, &in.u[i], sizeof uf);
    std::memcpy(&vf, &in.v[i], sizeof vf);
    u = __builtin_convertvector(uf, V);
    v = __builtin_convertvector(vf, V);
  } else {
    gather(u, [&](int k) { return double(in.u[at[k]]); });
    gather(v, [&](int k) { return double(in.v[at[k]]); });
  }
  const V hw[3] = {1.0 - u - v, u, v};
  // The codec (core/codec.h), L::n samples at a time: the per-pixel frame, the hit normal
  // interpolated with the hit's barycentrics (it goes in at its own length: the encoding
  // normalizes its result), the encoding.
  codec::Frame<V> f;
  codec::per_pixel_frame(f, b, n, t, tw, zero);
  V3 h;
  codec::interpolate(h, hw, hn, zero);
  V hh;
  dot(hh, h, h);
  codec::Encoding<V> e;
  codec::encode_in_frame(e, f, h);
  // inv, negated where det is not positive (encode_tangent_normal's -inv): its sign bit flipped.
  const M sign_bit = M{} + INT64_MIN;
  M inv_bits;
  std::memcpy(&inv_bits, &e.inv, sizeof e.inv);
  inv_bits ^= ~(e.det > zero) & sign_bit;
  V s;
  std::memcpy(&s, &inv_bits, sizeof s);
  V3 r;
  codec::scaled(r, e.x, s);
  // Degenerate: a miss, a short hit normal, an encoding not to be trusted.
  M good;
  codec::trusted(good, e);
  good &= hh > kShortHitNormal2;
  const unsigned bad = (~bits(good) | miss) & ((1u << kN) - 1u);
  if (full) {
    std::memcpy(&value[0][i], &r.x, sizeof(V));
    std::memcpy(&value[1][i], &r.y, sizeof(V));
    std::memcpy(&value[2][i], &r.z, sizeof(V));
    store_lane_flags<kN>(&degenerate[i], bad);
  } else {
    for (std::size_t k = 0; i + k < count; ++k) {
      value[0][i + k] = r.x[k];
      value[1][i + k] = r.y[k];
      value[2][i + k] = r.z[k];
      degenerate[i + k] = std::uint8_t(bad >> k & 1u);
    }
  }
}

// Every block of L::n samples.
template <typename L>
[[gnu::always_inline]] inline void encode_blocks(const LowTriangle* low, const glm::vec3* high_corner_normals,
                                                 const ShadeSamples& samples, std::size_t count, double* const value[3],
                                                 std::uint8_t* degenerate) {
  constexpr int kN = L::n;
  const std::int32_t* lt = samples.low_tri;
  for (std::size_t i = 0; i < count; i += kN) {
    bool same = i + kN <= count;
    for (int k = 1; k < kN && same; ++k) same = lt[i + std::size_t(k)] == lt[i];
    if (same) encode_block<L, true>(low, high_corner_normals, samples, i, count, value, degenerate);
    else encode_block<L, false>(low, high_corner_normals, samples, i, count, value, degenerate);
  }
}

// Two versions, chosen once at load time by the CPU: AVX2 (4 lanes per instruction) and the
// baseline (2 lanes per SSE2 instruction).
__attribute__((target_clones("avx2", "default"))) void encode_by_4(const LowTriangle* low, const glm::vec3* high_corner_normals,
                                                                   const ShadeSamples& samples, std::size_t count,
                                                                   double* const value[3], std::uint8_t* degenerate) {
  encode_blocks<Lanes4>(low, high_corner_normals, samples, count, value, degenerate);
}

// AVX-512 (x86-64-v4), 8 lanes per instruction.
__attribute__((target("arch=x86-64-v4"))) void encode_by_8(const LowTriangle* low, const glm::vec3* high_corner_normals,
                                                           const ShadeSamples& samples, std::size_t count, double* const value[3],
                                                           std::uint8_t* degenerate) {
  encode_blocks<Lanes8>(low, high_corner_normals, samples, count, value, degenerate);
}

}  // namespace

// The widest version the CPU runs (or the one `lanes` asks for). None uses FMA (-ffp-contract=off
// for this library: x86-64-v4 has it), so all give the scalar code's bits.
void encode_hits_per_pixel(const LowTriangle* low, const glm::vec3* high_corner_normals, const ShadeSamples& samples,
                           std::size_t count, double* const value[3], std::uint8_t* degenerate, int lanes) {
  if (lanes == 8 || (lanes == 0 && has_x86_64_v4())) encode_by_8(low, high_corner_normals, samples, count, value, degenerate);
  else encode_by_4(low, high_corner_normals, samples, count, value, degenerate);
}

bool kernel_lanes_available(int lanes) { return lanes == 4 || (lanes == 8 && has_x86_64_v4()); }

}  // namespace nmbake
