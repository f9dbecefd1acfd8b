// Directions for the bake's secondary rays (ambient occlusion, bent normals, thickness): the
// cosine-weighted hemisphere and a counter-based random stream that feeds it.
//
// Orthonormal basis: Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin 2017, "Building an
// Orthonormal Basis, Revisited" (JCGT 6(1)), the branch on the sign of n.z that keeps Frisvad's
// 2012 construction finite at n = (0, 0, -1). Disk: Shirley and Chiu 1997, "A Low Distortion Map
// Between Disk and Square" (concentric map). Hemisphere: Malley's method, the disk's uniform
// points lifted onto the hemisphere, which makes them cosine-distributed (pdf cos(theta) / pi).
//
// Every function here is deterministic, has no state beyond its arguments and gives finite
// results for every finite input. Directions are in the space of the normal given (object space
// for the bake's high-poly normals), unit length.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace nmbake {

// A right-handed orthonormal basis (t, b, n) around the direction n (any length; normalised here;
// zero or not finite: +z). Continuous in n within each half-space n.z >= 0 and n.z < 0 (the
// -0.0 of n.z counts as negative), with derivatives bounded there; it switches across the plane
// n.z = 0. No basis can be continuous over the whole sphere (the hairy ball theorem); this one
// is finite everywhere and as accurate at n = (0, 0, -1) as at (0, 0, 1).
inline void orthonormal_basis(const glm::dvec3& n_in, glm::dvec3& t, glm::dvec3& b, glm::dvec3& n) {
  const double len = glm::length(n_in);
  n = len > 0.0 && std::isfinite(len) ? n_in / len : glm::dvec3(0.0, 0.0, 1.0);
  // 1 / (sign + n.z) has |sign + n.z| >= 1: no cancellation anywhere.
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::dvec3(c, sign + n.y * n.y * a, -n.y);
}

// sin and cos of an angle t with |t| <= pi / 4 (the concentric map's), by their Taylor series to
// the terms in t^17 and t^18 (the first left out is below 2^-60 of the value there): within a unit
// in the last place of the true values (checked against the library on 10^7 angles), the same on
// every machine, and inlined, where the library's sincos is a call in the middle of every ray's
// arithmetic.
// For a double, or for a vector of doubles lane by lane (hemisphere.cpp: the same operations in the
// same order, so the same bits).
template <typename T>
[[gnu::always_inline]] inline void sin_cos_quarter(const T& t, T& s, T& c) {
  // Horner in t^2 over the series' coefficients (-1)^k / (2k + 1)! and (-1)^k / (2k)!.
  constexpr double kSin[] = {1.0,
                             -1.0 / 6.0,
                             1.0 / 120.0,
                             -1.0 / 5040.0,
                             1.0 / 362880.0,
                             -1.0 / 39916800.0,
                             1.0 / 6227020800.0,
                             -1.0 / 1307674368000.0,
                             1.0 / 355687428096000.0};
  constexpr double kCos[] = {1.0,
                             -1.0 / 2.0,
                             1.0 / 24.0,
                             -1.0 / 720.0,
                             1.0 / 40320.0,
                             -1.0 / 3628800.0,
                             1.0 / 479001600.0,
                             -1.0 / 87178291200.0,
                             1.0 / 20922789888000.0,
                             -1.0 / 6402373705728000.0};
  const T t2 = t * t;
  T ps = T{} + kSin[8], pc = T{} + kCos[9];  // T{} + x: x itself, in every lane of a vector
  for (int k = 7; k >= 0; --k) ps = ps * t2 + kSin[k];
  for (int k = 8; k >= 0; --k) pc = pc * t2 + kCos[k];
  s = t * ps;
  c = pc;
}

// The point of the unit disk for (u1, u2) in [0, 1)^2, by the concentric map: uniform in area for
// uniform (u1, u2), and neighbouring squares go to neighbouring disk cells (stratified inputs stay
// stratified). The angle is pi/4 times a ratio in [-1, 1] within each quarter (sin_cos_quarter);
// the quarters above and below turn it by pi/2, which swaps sin and cos.
inline glm::dvec2 concentric_disk(double u1, double u2) {
  const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
  if (a == 0.0 && b == 0.0) return glm::dvec2(0.0);
  constexpr double quarter_pi = 0.78539816339744830962;
  double s, c;
  if (std::fabs(a) > std::fabs(b)) {  // phi = pi/4 b/a
    sin_cos_quarter(quarter_pi * (b / a), s, c);
    return glm::dvec2(a * c, a * s);
  }
  sin_cos_quarter(quarter_pi * (a / b), s, c);  // phi = pi/2 - pi/4 a/b: cos phi = sin, sin phi = cos
  return glm::dvec2(b * s, b * c);
}

// cosine_direction (below) in a basis made once by orthonormal_basis (t, b, n): many directions
// about one normal pay for its basis once.
inline glm::dvec3 cosine_direction(const glm::dvec3& t, const glm::dvec3& b, const glm::dvec3& n, double u1, double u2) {
  const glm::dvec2 d = concentric_disk(u1, u2);
  // max(0, .) by a comparison, which the compiler inlines (std::fmax is a library call here, in
  // the middle of every ray's arithmetic); the same value for every input, NaN included (0).
  const double h = 1.0 - d.x * d.x - d.y * d.y;
  const double z = std::sqrt(h > 0.0 ? h : 0.0);
  return d.x * t + d.y * b + z * n;
}

// cosine_direction(t, b, n, u1[i], u2[i]) rounded to float, for i < count, into x[i], y[i], z[i]:
// the same bits, four at a time (hemisphere.cpp; an AVX2 clone where the processor has it).
void cosine_directions(const glm::dvec3& t, const glm::dvec3& b, const glm::dvec3& n, const double* u1, const double* u2,
                       std::size_t count, float* x, float* y, float* z);

// The cosine-weighted direction over the hemisphere around n for (u1, u2) uniform in [0, 1)^2:
// unit length (to rounding), dot(direction, n) >= 0 up to rounding (about 0 only on the disk's
// rim: grazing), density cos(theta) / pi over the hemisphere, so its mean is
// (2/3) n. n need not be unit (normalised here; zero or not finite: +z). Computed in double.
inline glm::dvec3 cosine_direction(const glm::dvec3& n_in, double u1, double u2) {
  glm::dvec3 t, b, n;
  orthonormal_basis(n_in, t, b, n);
  return cosine_direction(t, b, n, u1, u2);
}

// The same for a float normal, rounded to float for a ray's direction.
inline glm::vec3 cosine_direction(const glm::vec3& n, double u1, double u2) {
  return glm::vec3(cosine_direction(glm::dvec3(n), u1, u2));
}

// A 64-bit mixing function: a bijection of the 64-bit integers in which every input bit changes
// each output bit with probability close to 1/2. Two rounds of xor-shift and multiply by odd
// constants, then a final xor-shift; the shifts and multipliers are those of Stafford's "variant
// 13" finalizer (his 2011 search over MurmurHash3's finalizer parameters).
inline std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

// The key of one stream of the bake: distinct (texel, sample, map) give distinct, unrelated keys
// (mix64 is a bijection, so for one map and texel every sample gets its own key; across texels
// a repeat has probability about 2^-64).
inline std::uint64_t sample_key(std::uint64_t texel, std::uint64_t sample, std::uint64_t map) {
  return mix64(mix64(mix64(map) + texel) + sample);
}

// Uniform doubles in [0, 1) from a key, counter-based: value i is mix64 of the key's hash plus
// i + 1 steps of an odd increment (the golden ratio's 64-bit fraction), its top 53 bits scaled
// by 2^-53. Equal keys give equal streams, whatever thread or order they are made in; a stream
// repeats after 2^64 values. No global state; copying a stream copies its position.
class SampleStream {
 public:
  explicit SampleStream(std::uint64_t key) : state_(mix64(key ^ 0x6a09e667f3bcc909ull)) {}
  double next() {
    state_ += 0x9e3779b97f4a7c15ull;
    return double(mix64(state_) >> 11) * 0x1.0p-53;
  }
  // Two values at once, for cosine_direction.
  glm::dvec2 next2() {
    const double u1 = next();
    return glm::dvec2(u1, next());
  }

 private:
  std::uint64_t state_;
};

// The depth to which owen_scramble permutes exactly: 2^12 intervals a side, one for each of the
// first 4096 points of a sequence on each axis (each axis of a (0, m, 2)-net has one point in each
// interval of depth m), more than a texel's chain casts short of --ao-rays 16384. Below it each
// value's bits are drawn from a hash of the whole value (a point alone in its interval: the same as
// scrambling on; several: independent within it, never equal).
constexpr int kOwenDepth = 12;

// Sobol's first dimension: the bits of index reversed (van der Corput's radical inverse in base 2),
// as a 32-bit fixed-point value in [0, 1).
inline std::uint32_t sobol_radical_inverse(std::uint32_t index) {
  std::uint32_t x = index;
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}

// Sobol's second dimension: the direction numbers v_0 = 2^31, v_i = v_{i-1} xor (v_{i-1} >> 1).
inline std::uint32_t sobol_second(std::uint32_t index) {
  std::uint32_t x = 0, v = 0x80000000u;
  for (; index; index >>= 1, v ^= v >> 1) x ^= v & (0u - (index & 1u));
  return x;
}

// An axis's seed with the hash of the interval of depth 0 (the whole [0, 1)), which every value
// of the axis reads: made once for many values (owen_scramble's first hash, skipped).
struct OwenSeed {
  std::uint64_t seed = 0, top = 0;
};
inline OwenSeed owen_seed(std::uint64_t seed) { return {seed, mix64(seed ^ 0x9e3779b97f4a7c15ull)}; }

// The six flips of a block of depths: bit t (from the top) is the bit of h at the heap index of
// the interval at depth t the six bits `below` lead to (2^t plus their top t bits).
inline std::uint32_t owen_flips(std::uint64_t h, std::uint32_t below) {
  std::uint32_t flips = 0;
  for (int t = 0; t < 6; ++t) flips = flips << 1 | std::uint32_t((h >> ((1u << t) | (below >> (6 - t)))) & 1u);
  return flips;
}

// The nested uniform scramble of a 32-bit fixed-point value in [0, 1), to a double in [0, 1). Each
// interval of the subdivision (to kOwenDepth) swaps its halves or not by one bit of a hash: one
// 64-bit hash per interval at depths 0 and 6 gives the 63 bits of the intervals of the six depths
// from it (1 + 2 + ... + 32), so a value costs three hashes (the third for the bits below), not 13, or two with the
// depth-0 hash made once (OwenSeed).
inline double owen_scramble(std::uint32_t x, const OwenSeed& s) {
  static_assert(kOwenDepth == 12, "two blocks of six depths");
  // Depths 0 .. 5: the interval of depth 0 is the same for every x (OwenSeed::top). Depths 6 ..
  // 11: the interval of depth 6 holding x, its top 6 bits tagged by a leading 1 (a heap index).
  std::uint32_t out = x ^ (owen_flips(s.top, x >> 26) << 26);
  const std::uint64_t node = (std::uint64_t(1) << 6) | std::uint64_t(x >> 26);
  out ^= owen_flips(mix64(s.seed ^ (node * 0x9e3779b97f4a7c15ull)), (x << 6) >> 26) << 20;
  const std::uint64_t low =
      mix64(s.seed ^ (std::uint64_t(x) * 0xd1b54a32d192ed03ull) ^ 0x5851f42d4c957f2dull) >> (64 - (53 - kOwenDepth));
  return double((std::uint64_t(out >> (32 - kOwenDepth)) << (53 - kOwenDepth)) | low) * 0x1.0p-53;
}
inline double owen_scramble(std::uint32_t x, std::uint64_t seed) { return owen_scramble(x, owen_seed(seed)); }

// Point `index` of the first two dimensions of Sobol's sequence (the (0, 2)-sequence in base 2:
// van der Corput's radical inverse, and the dimension whose generator is Pascal's triangle mod 2),
// Owen-scrambled by `seed` (Owen 1995, "Randomly permuted (t,m,s)-nets and (t,s)-sequences"): at
// every depth d of the binary subdivision of each axis, the intervals' halves swap or not by a hash
// of the seed and the interval, so every point is uniform in [0, 1)^2 while the points 0 .. 2^m - 1
// stay a (0, m, 2)-net (one point in each of the 2^m elementary rectangles of area 2^-m). For an
// integrand with a discontinuity along a curve (visibility), the mean of n such points has variance
// of order n^-1.5 against n^-1 for independent points; distinct seeds give independent sets.
// Values in [0, 1); equal (index, seed) give equal points, in any thread.
// The seeds of the two axes come from `seed` by scramble_seeds; a caller drawing many points of one
// set makes them once and calls the second form.
inline void scramble_seeds(std::uint64_t seed, std::uint64_t& seed_x, std::uint64_t& seed_y) {
  seed_x = mix64(seed ^ 0x243f6a8885a308d3ull);
  seed_y = mix64(seed ^ 0x13198a2e03707344ull);
}
inline glm::dvec2 scrambled_sobol2(std::uint32_t index, const OwenSeed& seed_x, const OwenSeed& seed_y) {
  return glm::dvec2(owen_scramble(sobol_radical_inverse(index), seed_x), owen_scramble(sobol_second(index), seed_y));
}
// scrambled_sobol2(index[i], seeds[2 * chain[i]], seeds[2 * chain[i] + 1]) for i < count, into
// u1[i], u2[i]: points of several sets at once (a texel's chains), the same bits, four at a time
// (hemisphere.cpp; an AVX2 clone where the processor has it).
void scrambled_sobol2_many(const std::uint32_t* index, const std::uint8_t* chain, const OwenSeed* seeds, std::size_t count,
                           double* u1, double* u2);
inline glm::dvec2 scrambled_sobol2(std::uint32_t index, std::uint64_t seed_x, std::uint64_t seed_y) {
  return scrambled_sobol2(index, owen_seed(seed_x), owen_seed(seed_y));
}
inline glm::dvec2 scrambled_sobol2(std::uint32_t index, std::uint64_t seed) {
  std::uint64_t sx, sy;
  scramble_seeds(seed, sx, sy);
  return scrambled_sobol2(index, sx, sy);
}

}  // namespace nmbake
