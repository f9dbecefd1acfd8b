#include "shade_batch.h"

#include <algorithm>
#include <cmath>

#include "lanes.h"

namespace nmbake {

using namespace lanes;

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
      gather(b[c], [&](int k) { return sp[k]->b[c]; });
      gather(n[c].x, [&](int k) { return lp[k]->n[c].x; });
      gather(n[c].y, [&](int k) { return lp[k]->n[c].y; });
      gather(n[c].z, [&](int k) { return lp[k]->n[c].z; });
      gather(t[c].x, [&](int k) { return lp[k]->t[c].x; });
      gather(t[c].y, [&](int k) { return lp[k]->t[c].y; });
      gather(t[c].z, [&](int k) { return lp[k]->t[c].z; });
      gather(tw[c], [&](int k) { return lp[k]->t[c].w; });
      gather(hn[c].x, [&](int k) { return double(hp[k][c].x); });
      gather(hn[c].y, [&](int k) { return double(hp[k][c].y); });
      gather(hn[c].z, [&](int k) { return double(hp[k][c].z); });
    }
    V u, v;
    gather(u, [&](int k) { return double(sp[k]->u); });
    gather(v, [&](int k) { return double(sp[k]->v); });
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
