#include "shade_batch.h"

#include <algorithm>
#include <cmath>

// GCC 12 reports the vectors filled lane by lane in `lanes` as "maybe uninitialized" in the AVX2
// clone; every lane is written before use (all four are assigned at once).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace nmbake {
namespace {

// Four doubles, one per sample. Plain IEEE operations lane by lane: no reassociation and no fused
// multiply-add (the project builds with ISO C++, where GCC does not contract), so each lane rounds
// exactly as the scalar code does. The helpers take and give vectors by reference only: a 32-byte
// vector passed by value would change the calling convention between the AVX2 and baseline clones
// (clang refuses that outright).
typedef double V __attribute__((vector_size(32)));
constexpr int kLanes = 4;

struct V3 {
  V x, y, z;
};

[[gnu::always_inline]] inline void cross(V3& r, const V3& a, const V3& b) {  // glm::cross, term for term
  r.x = a.y * b.z - b.y * a.z;
  r.y = a.z * b.x - b.z * a.x;
  r.z = a.x * b.y - b.x * a.y;
}
[[gnu::always_inline]] inline void dot(V& r, const V3& a, const V3& b) {  // glm::dot: (x + y) + z of the products
  r = a.x * b.x + a.y * b.y + a.z * b.z;
}
// One vector from four scalars, built in registers.
template <typename F>
[[gnu::always_inline]] inline void lanes(V& r, F f) {
  r = V{f(0), f(1), f(2), f(3)};
}
[[gnu::always_inline]] inline void vsqrt(V& r, const V& a) {
  for (int k = 0; k < kLanes; ++k) r[k] = std::sqrt(a[k]);
}

}  // namespace

// Two versions, chosen once at load time by the CPU: AVX2 (4 lanes per instruction) and the
// baseline (2 lanes per SSE2 instruction). Neither uses FMA, so both give the scalar code's bits.
__attribute__((target_clones("avx2", "default"))) void encode_hits_per_pixel(
    const LowTriangle* low, const glm::vec3* high_corner_normals, const HitSample* samples, std::size_t count,
    glm::dvec3* value, std::uint8_t* degenerate) {
  const V zero = {0.0, 0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < count; i += kLanes) {
    // Gather, building each vector from four scalars in registers (lane stores followed by a
    // vector load would stall on store forwarding). A short last block repeats its last sample.
    const HitSample* sp[kLanes];
    const LowTriangle* lp[kLanes];
    const glm::vec3* hp[kLanes];
    for (int k = 0; k < kLanes; ++k) {
      sp[k] = &samples[std::min(i + std::size_t(k), count - 1)];
      lp[k] = &low[sp[k]->low_tri];
      hp[k] = &high_corner_normals[3 * std::size_t(sp[k]->high_tri)];
    }
    V b[3]{}, tw[3]{};
    V3 n[3]{}, t[3]{}, hn[3]{};
    for (int c = 0; c < 3; ++c) {
      lanes(b[c], [&](int k) { return sp[k]->b[c]; });
      lanes(n[c].x, [&](int k) { return lp[k]->n[c].x; });
      lanes(n[c].y, [&](int k) { return lp[k]->n[c].y; });
      lanes(n[c].z, [&](int k) { return lp[k]->n[c].z; });
      lanes(t[c].x, [&](int k) { return lp[k]->t[c].x; });
      lanes(t[c].y, [&](int k) { return lp[k]->t[c].y; });
      lanes(t[c].z, [&](int k) { return lp[k]->t[c].z; });
      lanes(tw[c], [&](int k) { return lp[k]->t[c].w; });
      lanes(hn[c].x, [&](int k) { return double(hp[k][c].x); });
      lanes(hn[c].y, [&](int k) { return double(hp[k][c].y); });
      lanes(hn[c].z, [&](int k) { return double(hp[k][c].z); });
    }
    V u, v;
    lanes(u, [&](int k) { return double(sp[k]->u); });
    lanes(v, [&](int k) { return double(sp[k]->v); });
    const V hw[3] = {1.0 - u - v, u, v};
    // interpolate_frame, per-pixel bitangent: sums start from zero as there.
    V3 fn{zero, zero, zero}, ft{zero, zero, zero};
    V sign = zero;
    for (int c = 0; c < 3; ++c) {
      fn.x += b[c] * n[c].x;
      fn.y += b[c] * n[c].y;
      fn.z += b[c] * n[c].z;
      ft.x += b[c] * t[c].x;
      ft.y += b[c] * t[c].y;
      ft.z += b[c] * t[c].z;
      sign += b[c] * tw[c];
    }
    V3 nt;
    cross(nt, fn, ft);
    const V3 fb{sign * nt.x, sign * nt.y, sign * nt.z};
    // The hit normal, interpolated with the hit's barycentrics and normalized.
    V3 h{zero, zero, zero};
    for (int c = 0; c < 3; ++c) {
      h.x += hw[c] * hn[c].x;
      h.y += hw[c] * hn[c].y;
      h.z += hw[c] * hn[c].z;
    }
    V hh, hlen;
    dot(hh, h, h);
    vsqrt(hlen, hh);
    h = {h.x / hlen, h.y / hlen, h.z / hlen};
    // encode_tangent_normal.
    V3 bxn, nxt, txb;
    cross(bxn, fb, fn);
    cross(nxt, fn, ft);
    cross(txb, ft, fb);
    V det, tt, bb, nn;
    dot(det, ft, bxn);
    dot(tt, ft, ft);
    dot(bb, fb, fb);
    dot(nn, fn, fn);
    const V scale2 = tt * bb * nn;
    V3 x;
    dot(x.x, h, bxn);
    dot(x.y, h, nxt);
    dot(x.z, h, txb);
    x = {x.x / det, x.y / det, x.z / det};
    V xx, len;
    dot(xx, x, x);
    vsqrt(len, xx);
    const V3 r{x.x / len, x.y / len, x.z / len};
    for (int k = 0; k < kLanes && i + k < count; ++k) {
      const bool bad = !(hlen[k] > 1e-12) || !(det[k] * det[k] > 1e-24 * scale2[k]) || !std::isfinite(det[k]) ||
                       !(len[k] > 0.0) || !std::isfinite(len[k]);
      degenerate[i + k] = bad;
      value[i + k] = glm::dvec3(r.x[k], r.y[k], r.z[k]);
    }
  }
}

}  // namespace nmbake
