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

// The point of the unit disk for (u1, u2) in [0, 1)^2, by the concentric map: uniform in area for
// uniform (u1, u2), and neighbouring squares go to neighbouring disk cells (stratified inputs stay
// stratified).
inline glm::dvec2 concentric_disk(double u1, double u2) {
  const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
  if (a == 0.0 && b == 0.0) return glm::dvec2(0.0);
  constexpr double quarter_pi = 0.78539816339744830962;
  double r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = quarter_pi * (b / a);
  } else {
    r = b;
    phi = 2.0 * quarter_pi - quarter_pi * (a / b);
  }
  return glm::dvec2(r * std::cos(phi), r * std::sin(phi));
}

// The cosine-weighted direction over the hemisphere around n for (u1, u2) uniform in [0, 1)^2:
// unit length (to rounding), dot(direction, n) >= 0 up to rounding (about 0 only on the disk's
// rim: grazing), density cos(theta) / pi over the hemisphere, so its mean is
// (2/3) n. n need not be unit (normalised here; zero or not finite: +z). Computed in double.
inline glm::dvec3 cosine_direction(const glm::dvec3& n_in, double u1, double u2) {
  glm::dvec3 t, b, n;
  orthonormal_basis(n_in, t, b, n);
  const glm::dvec2 d = concentric_disk(u1, u2);
  const double z = std::sqrt(std::fmax(0.0, 1.0 - d.x * d.x - d.y * d.y));
  return d.x * t + d.y * b + z * n;
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

}  // namespace nmbake
