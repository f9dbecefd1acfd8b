#include "core/hemisphere.h"

#include <cstring>

#include "core/lanes.h"

namespace nmbake {

namespace {

using lanes::kLanes;
using lanes::M;
using lanes::V;

// out = m ? a : b per lane (by reference: a 32-byte vector by value changes the calling convention).
[[gnu::always_inline]] inline void select(V& out, const M& m, const V& a, const V& b) { out = m ? a : b; }

// Four unsigned 64-bit lanes: the integer side of scrambled_sobol2, lane for lane as hemisphere.h
// writes it for one value (32-bit values held in the low half, with the 32-bit wrap made explicit).
typedef std::uint64_t U __attribute__((vector_size(32)));

[[gnu::always_inline]] inline void mix64(U& x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
}

// owen_flips per lane.
[[gnu::always_inline]] inline void owen_flips(U& flips, const U& h, const U& below) {
  flips = U{} + 0u;
  for (unsigned t = 0; t < 6; ++t) flips = flips << 1 | ((h >> ((U{} + (1u << t)) | (below >> (6 - t)))) & 1u);
}

// owen_scramble per lane (x: 32-bit values), the double of each.
[[gnu::always_inline]] inline void owen_scramble(V& out, const U& x, const U& seed, const U& top) {
  U flips, out_bits, h = seed, low;
  owen_flips(flips, top, x >> 26);
  out_bits = x ^ (flips << 26);
  h ^= ((x >> 26) | (U{} + 64u)) * 0x9e3779b97f4a7c15ull;
  mix64(h);
  owen_flips(flips, h, ((x << 6) & 0xffffffffu) >> 26);
  out_bits ^= flips << 20;
  low = seed ^ (x * 0xd1b54a32d192ed03ull) ^ 0x5851f42d4c957f2dull;
  mix64(low);
  const U bits = ((out_bits >> (32 - kOwenDepth)) << (53 - kOwenDepth)) | (low >> (64 - (53 - kOwenDepth)));
  // double(bits) without a conversion per lane: bits < 2^53 as hi * 2^26 + lo, each part below
  // 2^52 made a double by setting the exponent of 2^52 over it (x + 2^52 exactly) and taking 2^52
  // off; every step is exact, so the sum is the conversion's value.
  const U two52 = U{} + 0x4330000000000000ull;
  V hi, lo;
  const U hi_bits = (bits >> 26) | two52, lo_bits = (bits & 0x3ffffffu) | two52;
  std::memcpy(&hi, &hi_bits, sizeof hi);
  std::memcpy(&lo, &lo_bits, sizeof lo);
  out = ((hi - 0x1.0p52) * 0x1.0p26 + (lo - 0x1.0p52)) * 0x1.0p-53;
}

}  // namespace

__attribute__((target_clones("avx2", "default"))) void cosine_directions(const glm::dvec3& t, const glm::dvec3& b,
                                                                         const glm::dvec3& n, const double* u1, const double* u2,
                                                                         std::size_t count, float* x, float* y, float* z) {
  constexpr double quarter_pi = 0.78539816339744830962;
  std::size_t i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    V p, q;
    lanes::gather(p, [&](int k) { return u1[i + std::size_t(k)]; });
    lanes::gather(q, [&](int k) { return u2[i + std::size_t(k)]; });
    // concentric_disk, both of its branches: the wide quarters (|a| > |b|) take r = a and the
    // ratio b / a, the others r = b and a / b; sin and cos swap between them.
    const V a = 2.0 * p - 1.0, bb = 2.0 * q - 1.0;
    const V abs_a = a < 0.0 ? -a : a, abs_b = bb < 0.0 ? -bb : bb;
    const M wide = abs_a > abs_b;
    const M centre = (a == 0.0) & (bb == 0.0);
    V r, o, one_or_r, ratio, s, c, cs, sc, dx, dy;
    select(r, wide, a, bb);
    select(o, wide, bb, a);
    select(one_or_r, centre, V{} + 1.0, r);
    select(ratio, centre, V{}, o / one_or_r);
    const V angle = quarter_pi * ratio;
    sin_cos_quarter(angle, s, c);
    select(cs, wide, c, s);
    select(sc, wide, s, c);
    select(dx, centre, V{}, r * cs);
    select(dy, centre, V{}, r * sc);
    // cosine_direction: lifted onto the hemisphere, then into the basis, term for term.
    const V h = 1.0 - dx * dx - dy * dy;
    V h0, zz;
    select(h0, h > 0.0, h, V{});
    lanes::vsqrt(zz, h0);
    for (int k = 0; k < kLanes; ++k) {
      const std::size_t j = i + std::size_t(k);
      x[j] = float(dx[k] * t.x + dy[k] * b.x + zz[k] * n.x);
      y[j] = float(dx[k] * t.y + dy[k] * b.y + zz[k] * n.y);
      z[j] = float(dx[k] * t.z + dy[k] * b.z + zz[k] * n.z);
    }
  }
  for (; i < count; ++i) {
    const glm::vec3 d(cosine_direction(t, b, n, u1[i], u2[i]));
    x[i] = d.x, y[i] = d.y, z[i] = d.z;
  }
}

__attribute__((target_clones("avx2", "default"))) void scrambled_sobol2_many(const std::uint32_t* index,
                                                                             const std::uint8_t* chain, const OwenSeed* seeds,
                                                                             std::size_t count, double* u1, double* u2) {
  const std::size_t whole = count - count % kLanes;
  // Each axis in a pass of its own (fewer vectors live at once): the first dimension, the bits
  // reversed (sobol_radical_inverse, in 32 bits), scrambled by the chains' first seeds.
  for (std::size_t i = 0; i < whole; i += kLanes) {
    const U n = {index[i], index[i + 1], index[i + 2], index[i + 3]};
    U x = ((n << 16) & 0xffffffffu) | (n >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    U seed, top;
    for (int k = 0; k < kLanes; ++k) {
      const OwenSeed& a = seeds[2 * std::size_t(chain[i + std::size_t(k)])];
      seed[k] = a.seed, top[k] = a.top;
    }
    V p;
    owen_scramble(p, x, seed, top);
    std::memcpy(u1 + i, &p, sizeof p);
  }
  // The second (sobol_second: the direction numbers of every set bit, while a lane has one), by
  // the second seeds.
  for (std::size_t i = 0; i < whole; i += kLanes) {
    U y = U{} + 0u, rest = {index[i], index[i + 1], index[i + 2], index[i + 3]};
    std::uint32_t left = index[i] | index[i + 1] | index[i + 2] | index[i + 3];
    for (std::uint32_t v = 0x80000000u; left; left >>= 1, rest >>= 1, v ^= v >> 1) y ^= (U{} + v) & (U{} - (rest & 1u));
    U seed, top;
    for (int k = 0; k < kLanes; ++k) {
      const OwenSeed& b = seeds[2 * std::size_t(chain[i + std::size_t(k)]) + 1];
      seed[k] = b.seed, top[k] = b.top;
    }
    V p;
    owen_scramble(p, y, seed, top);
    std::memcpy(u2 + i, &p, sizeof p);
  }
  for (std::size_t i = whole; i < count; ++i) {
    const glm::dvec2 u = scrambled_sobol2(index[i], seeds[2 * std::size_t(chain[i])], seeds[2 * std::size_t(chain[i]) + 1]);
    u1[i] = u.x, u2[i] = u.y;
  }
}

}  // namespace nmbake
