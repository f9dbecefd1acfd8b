// Four doubles per vector (and eight, below), for the bake's per-sample arithmetic (shade_batch.cpp,
// tile_kernels.cpp).
//
// Plain IEEE operations lane by lane: no reassociation and no fused multiply-add (the project
// builds with ISO C++, where GCC does not contract), so each lane rounds exactly as the scalar code
// it mirrors does. The helpers take and give vectors by reference only: a 32-byte vector passed by
// value would change the calling convention between the AVX2 and baseline clones (clang refuses
// that outright). Internal to the baker core; include only from its .cpp files.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/codec.h"

// GCC 12 reports vectors built by gather() as "maybe uninitialized" in the AVX2 clones; every lane
// is written before use (all four are assigned at once). Off for the kernel files that include this.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The comparisons below (codec::Ops) return vectors: always inlined, they are never called across
// the clones' conventions -Wpsabi warns about (nmbake_trace, which instantiates codec.h's and
// rasterize.h's templates with them, is built with -Wno-psabi for the same reason).
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace nmbake::lanes {

typedef double V __attribute__((vector_size(32)));
typedef std::int64_t M __attribute__((vector_size(32)));  // comparison results: all ones or zero per lane
typedef float F __attribute__((vector_size(16)));
typedef std::int32_t I __attribute__((vector_size(16)));  // also the comparison results of F
constexpr int kLanes = 4;

using V3 = codec::Vec3<V>;
using codec::cross;  // glm::cross, term for term
using codec::dot;    // glm::dot: (x + y) + z of the products

// One vector from four scalars, built in registers (lane stores followed by a vector load would
// stall on store forwarding).
template <typename Fn>
[[gnu::always_inline]] inline void gather(V& r, Fn f) {
  r = V{f(0), f(1), f(2), f(3)};
}
[[gnu::always_inline]] inline void vsqrt(V& r, const V& a) {
  for (int k = 0; k < kLanes; ++k) r[k] = std::sqrt(a[k]);
}
// Bit k set for each lane k whose mask is set.
[[gnu::always_inline]] inline unsigned bits(const I& m) {
  const I t = m & I{1, 2, 4, 8};
  const I u = t | I{t[2], t[3], 0, 0};
  return unsigned(u[0] | u[1]);
}
[[gnu::always_inline]] inline unsigned bits(const M& m) {
  const I narrow = __builtin_convertvector(m, I);
  return bits(narrow);
}

// to[k] = bit k of `bits` (0 or 1) for the L lanes: per-lane flags stored at once.
template <int L>
[[gnu::always_inline]] inline void store_lane_flags(std::uint8_t* to, unsigned bits) {
  std::uint8_t flags[L];
  for (int k = 0; k < L; ++k) flags[k] = std::uint8_t(bits >> k & 1u);
  std::memcpy(to, flags, sizeof flags);
}

// Eight doubles per vector, for the kernels' AVX-512 versions only (x86-64-v4: one instruction per
// operation): the same helpers, overloaded on the wider types. Use them only in functions compiled
// for that target.
typedef double V8 __attribute__((vector_size(64)));
typedef std::int64_t M8 __attribute__((vector_size(64)));
typedef float F8 __attribute__((vector_size(32)));
typedef std::int32_t I8 __attribute__((vector_size(32)));

template <typename Fn>
[[gnu::always_inline]] inline void gather(V8& r, Fn f) {
  r = V8{f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)};
}
// Kept a loop (no unrolling) for GCC's loop vectorizer to make one vector square root of it (the
// kernels' library has no errno: -fno-math-errno); unrolled, the lanes were taken apart and the
// comparisons after them made one lane at a time (-O3 without SLP vectorization).
[[gnu::always_inline]] inline void vsqrt(V8& r, const V8& a) {
#pragma GCC unroll 1
  for (int k = 0; k < 8; ++k) r[k] = std::sqrt(a[k]);
}
// With vector operations (weighted, or-ed together), not a loop over the lanes.
[[gnu::always_inline]] inline unsigned bits(const I8& m) {
  const I8 t = m & I8{1, 2, 4, 8, 16, 32, 64, 128};
  const I u = __builtin_shufflevector(t, t, 0, 1, 2, 3) | __builtin_shufflevector(t, t, 4, 5, 6, 7);
  const I v = u | I{u[2], u[3], 0, 0};
  return unsigned(v[0] | v[1]);
}
[[gnu::always_inline]] inline unsigned bits(const M8& m) {
  const I8 narrow = __builtin_convertvector(m, I8);
  return bits(narrow);
}

// The vector types of one width, for kernels written once over it.
struct Lanes4 {
  using V = lanes::V;
  using M = lanes::M;
  using F = lanes::F;
  using I = lanes::I;
  static constexpr int n = 4;
};
struct Lanes8 {
  using V = V8;
  using M = M8;
  using F = F8;
  using I = I8;
  static constexpr int n = 8;
};

// Whether this CPU runs the kernels' AVX-512 (x86-64-v4) versions: AVX-512 F, VL, BW and DQ.
inline bool has_x86_64_v4() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  return yes;
}

}  // namespace nmbake::lanes

namespace nmbake::codec {
template <>
struct Ops<lanes::V> {
  using V = lanes::V;
  using M = lanes::M;
  [[gnu::always_inline]] static void root(V& r, const V& a) { lanes::vsqrt(r, a); }
  [[gnu::always_inline]] static M gt(const V& a, const V& b) { return a > b; }
  [[gnu::always_inline]] static M ge(const V& a, const V& b) { return a >= b; }
  [[gnu::always_inline]] static M lt(const V& a, const V& b) { return a < b; }
  [[gnu::always_inline]] static M le(const V& a, const V& b) { return a <= b; }
  [[gnu::always_inline]] static M invert(const M& m) { return ~m; }
};
// Eight lanes compared as two halves of four: GCC 12 made some eight-lane comparisons one lane at
// a time (a scalar compare, a set and an insert per lane), the halves take one instruction each.
template <>
struct Ops<lanes::V8> {
  using V8 = lanes::V8;
  using M8 = lanes::M8;
  using V = lanes::V;
  using M = lanes::M;
  [[gnu::always_inline]] static void root(V8& r, const V8& a) { lanes::vsqrt(r, a); }
  template <typename Fn>
  [[gnu::always_inline]] static M8 halves(const V8& a, const V8& b, Fn f) {
    const V al = __builtin_shufflevector(a, a, 0, 1, 2, 3), ah = __builtin_shufflevector(a, a, 4, 5, 6, 7);
    const V bl = __builtin_shufflevector(b, b, 0, 1, 2, 3), bh = __builtin_shufflevector(b, b, 4, 5, 6, 7);
    const M lo = f(al, bl), hi = f(ah, bh);
    return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
  }
  [[gnu::always_inline]] static M8 gt(const V8& a, const V8& b) {
    return halves(a, b, [](const V& x, const V& y) { return M(x > y); });
  }
  [[gnu::always_inline]] static M8 ge(const V8& a, const V8& b) {
    return halves(a, b, [](const V& x, const V& y) { return M(x >= y); });
  }
  [[gnu::always_inline]] static M8 lt(const V8& a, const V8& b) {
    return halves(a, b, [](const V& x, const V& y) { return M(x < y); });
  }
  [[gnu::always_inline]] static M8 le(const V8& a, const V8& b) {
    return halves(a, b, [](const V& x, const V& y) { return M(x <= y); });
  }
  [[gnu::always_inline]] static M8 invert(const M8& m) { return ~m; }
};
}  // namespace nmbake::codec
