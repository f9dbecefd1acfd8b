#include "tile_kernels.h"

#include <algorithm>
#include <cfloat>

#include "lanes.h"

namespace nmbake {

using namespace lanes;

namespace {

// P + front N and -N for one triangle at barycentrics w, as sample_rays does (low_point,
// low_ray_normal: b0 * c0 + b1 * c1 + b2 * c2 summed left to right, N times 1 / |N|). `good`: lanes
// whose squared normal length exceeds 1e-24 (the others take low_ray_normal's fallback).
[[gnu::always_inline]] inline void default_ray(const LowTriangle& lt, double front, const V (&w)[3], V3& org, V3& dir,
                                               unsigned& good) {
  V3 p, n;
  for (int c = 0; c < 3; ++c) {
    const V3 pc = {w[c] * lt.p[c].x, w[c] * lt.p[c].y, w[c] * lt.p[c].z};
    const V3 nc = {w[c] * lt.ray_n[c].x, w[c] * lt.ray_n[c].y, w[c] * lt.ray_n[c].z};
    if (c == 0) {
      p = pc;
      n = nc;
    } else {
      p = {p.x + pc.x, p.y + pc.y, p.z + pc.z};
      n = {n.x + nc.x, n.y + nc.y, n.z + nc.z};
    }
  }
  V len2, len;
  dot(len2, n, n);
  vsqrt(len, len2);
  const V inv = 1.0 / len;
  n = {n.x * inv, n.y * inv, n.z * inv};
  good = bits(len2 > 1e-24);
  org = {p.x + front * n.x, p.y + front * n.y, p.z + front * n.z};
  dir = {-n.x, -n.y, -n.z};
}

}  // namespace

// Two versions, chosen once at load time by the CPU: AVX2 and the SSE2 baseline. Neither uses FMA,
// so both give the scalar code's bits.
__attribute__((target_clones("avx2", "default"))) std::size_t cover_rect(const TexelTriangle& tt, std::int32_t t, int x0,
                                                                          int x1, int y0, int y1, double ox, double oy,
                                                                          const DefaultRays& rays, const SampleSlots& slots,
                                                                          std::size_t first, std::size_t row_stride) {
  std::size_t taken = 0;
  const V zero = {0.0, 0.0, 0.0, 0.0};
  for (int y = y0; y <= y1; ++y) {
    const double qy = y + oy;
    // Edge k's value at q is d.x * (q.y - a.y) - d.y * (q.x - a.x); the first product is the row's.
    double row_term[3];
    for (int k = 0; k < 3; ++k) row_term[k] = tt.edge_d[k].x * (qy - tt.edge_a[k].y);
    const std::size_t row = first + std::size_t(y - y0) * row_stride;
    for (int x = x0; x <= x1; x += kLanes) {
      const V qx = V{double(x), double(x + 1), double(x + 2), double(x + 3)} + ox;
      M in = {x <= x1 ? -1 : 0, x + 1 <= x1 ? -1 : 0, x + 2 <= x1 ? -1 : 0, x + 3 <= x1 ? -1 : 0};
      V w[3];
      for (int k = 0; k < 3; ++k) {
        const V e = row_term[k] - tt.edge_d[k].y * (qx - tt.edge_a[k].x);
        // covers() rejects e < 0 when the opposite corner is on the positive side, else e >= 0
        // (a NaN passes both tests there; the sum test below rejects it).
        in &= tt.edge_side[k] > 0.0 ? ~(e < zero) : ~(e >= zero);
        w[(k + 2) % 3] = e * tt.edge_inv_side[k];
      }
      const V sum = w[0] + w[1] + w[2];
      in &= (sum > zero) & (sum <= DBL_MAX);  // covers(): !(sum > 0) || !isfinite(sum) rejects
      const unsigned m = bits(in);
      if (!m) continue;
      const V inv_sum = 1.0 / sum;
      const V b[3] = {w[0] * inv_sum, w[1] * inv_sum, w[2] * inv_sum};
      V3 org{zero, zero, zero}, dir{zero, zero, zero};
      unsigned good = 0;
      if (rays.low) default_ray(rays.low[t], double(rays.front), b, org, dir, good);
      const F of[3] = {__builtin_convertvector(org.x, F), __builtin_convertvector(org.y, F),
                       __builtin_convertvector(org.z, F)};
      const F df[3] = {__builtin_convertvector(dir.x, F), __builtin_convertvector(dir.y, F),
                       __builtin_convertvector(dir.z, F)};
      for (int k = 0; k < kLanes; ++k) {
        if (!(m >> k & 1u)) continue;
        const std::size_t slot = row + std::size_t(x + k - x0);
        if (slots.tri[slot] >= 0) {
          ++taken;
          continue;
        }
        double bk[3] = {b[0][k], b[1][k], b[2][k]};
        const bool moved = inset_from_edges(bk);
        slots.tri[slot] = t;
        for (int c = 0; c < 3; ++c) slots.b[c][slot] = bk[c];
        if (!rays.low) continue;
        // A sample moved in from an edge has other barycentrics than the ray was made with.
        slots.ray_fallback[slot] = moved || !(good >> k & 1u);
        for (int c = 0; c < 3; ++c) {
          slots.org[c][slot] = of[c][k];
          slots.dir[c][slot] = df[c][k];
        }
      }
    }
  }
  return taken;
}

__attribute__((target_clones("avx2", "default"))) void write_texel_row(const TexelSums& sums, std::size_t first,
                                                                        int width, bool flip_y, double snap, float* rgb,
                                                                        std::uint8_t* covered) {
  const V zero = {0.0, 0.0, 0.0, 0.0};
  for (int x = 0; x < width; x += kLanes) {
    const int n = std::min(kLanes, width - x);
    V3 v;
    V count;
    gather(v.x, [&](int k) { return sums.sum[0][first + std::size_t(x + std::min(k, n - 1))]; });
    gather(v.y, [&](int k) { return sums.sum[1][first + std::size_t(x + std::min(k, n - 1))]; });
    gather(v.z, [&](int k) { return sums.sum[2][first + std::size_t(x + std::min(k, n - 1))]; });
    gather(count, [&](int k) { return sums.count[first + std::size_t(x + std::min(k, n - 1))]; });
    const unsigned filled = bits(count > zero);
    if (!filled) continue;
    // glm::length, then v * (1 / length); a zero sum gives (0, 0, 1).
    V len2, len;
    dot(len2, v, v);
    vsqrt(len, len2);
    const V inv = 1.0 / len;
    const M nonzero = len > zero;
    v.x = nonzero ? v.x * inv : zero;
    v.y = nonzero ? v.y * inv : zero;
    v.z = nonzero ? v.z * inv : zero + 1.0;
    if (flip_y) v.y = -v.y;
    V* const comp[3] = {&v.x, &v.y, &v.z};
    F out[3];
    for (int c = 0; c < 3; ++c) {
      V& u = *comp[c];
      const V mag = u < zero ? -u : u;
      u = mag < snap ? zero : u;
      out[c] = __builtin_convertvector(u * 0.5 + 0.5, F);
    }
    for (int k = 0; k < n; ++k) {
      if (!(filled >> k & 1u)) continue;
      for (int c = 0; c < 3; ++c) rgb[3 * std::size_t(x + k) + std::size_t(c)] = out[c][k];
      covered[x + k] = 1;
    }
  }
}

}  // namespace nmbake
