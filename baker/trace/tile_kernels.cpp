#include "trace/tile_kernels.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "core/lanes.h"

namespace nmbake {

using namespace lanes;

namespace {

// P + front N and -N for one triangle at barycentrics w: default_ray (shade_batch.h), as
// sample_rays makes it. `good`: lanes whose squared normal length exceeds 1e-24 (the others take
// low_ray_normal's fallback). V: the lanes' vector type (lanes.h).
template <typename V>
[[gnu::always_inline]] inline void default_ray_lanes(const LowTriangle& lt, double front, const V (&w)[3], codec::Vec3<V>& org,
                                                     codec::Vec3<V>& dir, unsigned& good) {
  codec::Vec3<V> p, n;
  V len2;
  low_point_and_normal(p, n, len2, lt, w);
  good = bits(codec::Ops<V>::gt(len2, V{} + 1e-24));
  default_ray(org, dir, p, n, front);
}

// The cage-first policy's inward ray with a cage for one triangle at barycentrics w: cage_ray and
// inward_ray (pipeline/rays.h), term for term. Besides origin and direction: the ray's far end,
// its base (the search distance) and where its preferred part begins. `good`: lanes whose cage
// point lies off the low-poly (the others take cage_ray's fallback direction).
template <typename V>
struct CageLanes {
  codec::Vec3<V> org, dir;
  V far, base, prefer_lo;
};
// a where m is set, else b (m: all ones or zero per lane), by the bits.
template <typename V, typename M>
[[gnu::always_inline]] inline V select(const M& m, const V& a, const V& b) {
  M ai, bi;
  std::memcpy(&ai, &a, sizeof ai);
  std::memcpy(&bi, &b, sizeof bi);
  const M r = (ai & m) | (bi & ~m);
  V out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}
template <typename V>
[[gnu::always_inline]] inline void weighted(V& r, const V (&w)[3], const double c[3]) {
  r = w[0] * c[0];
  r = r + w[1] * c[1];
  r = r + w[2] * c[2];
}
template <typename V>
[[gnu::always_inline]] inline void cage_ray_lanes(const LowTriangle& lt, const CageTriangle& ct, double diagonal, const V (&w)[3],
                                                  CageLanes<V>& r, unsigned& good) {
  codec::Vec3<V> p, pc;
  corner_sum(p, lt.p, w);
  corner_sum(pc, ct.corner, w);
  V rear, search;
  weighted(rear, w, ct.rear);
  weighted(search, w, ct.search);
  const codec::Vec3<V> d = {p.x - pc.x, p.y - pc.y, p.z - pc.z};
  V len2, len;
  dot(len2, d, d);
  vsqrt(len, len2);
  good = bits(codec::Ops<V>::gt(len, V{} + 1e-9 * diagonal));
  r.dir = {d.x / len, d.y / len, d.z / len};
  const V s = select(codec::Ops<V>::lt(len, search), search, len);  // std::max(len, search)
  r.org = {p.x - s * r.dir.x, p.y - s * r.dir.y, p.z - s * r.dir.z};
  r.far = s + rear;
  r.base = s;
  const V zero = {};
  r.prefer_lo = select(codec::Ops<V>::gt(s, len), s - len, zero);
}

// The texels x0 <= x <= x1 of one row whose sample at x offset ox can be covered, xa .. xb: each
// edge's value is linear in x, with one sign on one side of where it crosses 0 and the other on
// the other. The bounds have a margin far above the rounding of that crossing (relative to the
// terms it sums) and of the edge values near it; the coverage test decides every texel in them.
// row_term: each edge's first product at the row's sample height. Returns false when none can be.
[[gnu::always_inline]] inline bool row_bounds(const TexelTriangle& tt, const double row_term[3], const double inv_dy[3],
                                              double ox, int x0, int x1, int& xa, int& xb) {
  xa = x0, xb = x1;
  for (int k = 0; k < 3; ++k) {
    const double dy = tt.edge_d[k].y;
    if (dy == 0.0) continue;  // the edge's value does not change along the row
    const double along = row_term[k] * inv_dy[k];
    const double cross = tt.edge_a[k].x + along - ox;
    if (!(cross >= -DBL_MAX && cross <= DBL_MAX)) continue;  // not finite: no bound
    const double slack = 1e-6 * (1.0 + std::fabs(tt.edge_a[k].x) + std::fabs(along) + std::fabs(ox));
    if ((tt.edge_side[k] > 0.0) == (dy > 0.0)) {  // covered only up to the crossing
      const double hi = std::floor(cross + slack);
      if (hi < double(xa)) return false;
      if (hi < double(xb)) xb = int(hi);
    } else {  // covered only from the crossing on
      const double lo = std::ceil(cross - slack);
      if (lo > double(xb)) return false;
      if (lo > double(xa)) xa = int(lo);
    }
  }
  return true;
}

// L::n lanes of samples of triangle t (those `m` marks covered, barycentrics b before any inset)
// into slots slot0 .. slot0 + L::n - 1, with their rays when rays.low: each slot that already
// holds a triangle is left as it is and counted. Returns that count.
template <typename L>
[[gnu::always_inline]] inline std::size_t store_lanes(unsigned m, const typename L::V (&b)[3], std::int32_t t,
                                                      const KernelRays& rays, const SampleSlots& slots, std::size_t slot0) {
  using V = typename L::V;
  using M = typename L::M;
  using F = typename L::F;
  using I = typename L::I;
  constexpr int kN = L::n;
  constexpr unsigned kAll = (1u << kN) - 1u;
  // Each part computed only where used (zeroing the lanes of them all cost as much as a third of
  // the kernel at eight lanes).
  CageLanes<V> cr;
  unsigned good = 0;
  F of[3], df[3], far, lo;
  if (rays.low) {
    if (rays.cage) {
      cage_ray_lanes(rays.low[t], rays.cage[t], rays.diagonal, b, cr, good);
      far = __builtin_convertvector(cr.far, F);
      lo = __builtin_convertvector(cr.prefer_lo, F);
    } else {
      default_ray_lanes(rays.low[t], double(rays.front), b, cr.org, cr.dir, good);
    }
    of[0] = __builtin_convertvector(cr.org.x, F), of[1] = __builtin_convertvector(cr.org.y, F);
    of[2] = __builtin_convertvector(cr.org.z, F);
    df[0] = __builtin_convertvector(cr.dir.x, F), df[1] = __builtin_convertvector(cr.dir.y, F);
    df[2] = __builtin_convertvector(cr.dir.z, F);
  }
  if (m == kAll) {
    // The common case, all lanes at once: every sample covered, their slots free, none near
    // enough to an edge to be moved in (inset_from_edges leaves them as they are).
    I held;
    std::memcpy(&held, &slots.tri[slot0], sizeof held);
    const V inset = V{} + kEdgeInset;
    const M far_from_edges = codec::Ops<V>::ge(b[0], inset) & codec::Ops<V>::ge(b[1], inset) & codec::Ops<V>::ge(b[2], inset);
    if (bits(held < 0) == kAll && bits(far_from_edges) == kAll) {
      const I tris = I{} + t;
      std::memcpy(&slots.tri[slot0], &tris, sizeof tris);
      for (int c = 0; c < 3; ++c) std::memcpy(&slots.b[c][slot0], &b[c], sizeof(V));
      if (!rays.low) return 0;
      for (int c = 0; c < 3; ++c) {
        std::memcpy(&slots.org[c][slot0], &of[c], sizeof(F));
        std::memcpy(&slots.dir[c][slot0], &df[c], sizeof(F));
      }
      if (rays.cage) {
        std::memcpy(&slots.tfar[slot0], &far, sizeof(F));
        std::memcpy(&slots.base[slot0], &cr.base, sizeof(V));
        std::memcpy(&slots.prefer_lo[slot0], &lo, sizeof(F));
      }
      store_lane_flags<kN>(&slots.ray_fallback[slot0], ~good);
      return 0;
    }
  }
  std::size_t taken = 0;
  for (int k = 0; k < kN; ++k) {
    if (!(m >> k & 1u)) continue;
    const std::size_t slot = slot0 + std::size_t(k);
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
    if (rays.cage) {
      slots.tfar[slot] = far[k];
      slots.base[slot] = cr.base[k];
      slots.prefer_lo[slot] = lo[k];
    }
  }
  return taken;
}

// covers() (core/rasterize.h) for the lanes `in` marks, at qx on a row whose edges' first products
// are row_term (one per edge, or per lane): the covered lanes as bits, and their barycentrics in b.
template <typename V, typename M, typename Row>
[[gnu::always_inline]] inline unsigned covered_lanes(M in, V (&b)[3], const TexelTriangle& tt, const Row (&row_term)[3],
                                                     const V& qx, const V& zero) {
  V w[3], sum;
  edge_weights(in, w, tt, row_term, qx, zero);
  weight_sum(in, sum, w, zero);
  const unsigned m = bits(in);
  if (m) normalize_weights(b, w, sum);
  return m;
}

// 1 / d.y of each edge, for row_bounds (which need not be exact).
[[gnu::always_inline]] inline void inverse_dy(const TexelTriangle& tt, double inv_dy[3]) {
  for (int k = 0; k < 3; ++k) inv_dy[k] = tt.edge_d[k].y != 0.0 ? 1.0 / tt.edge_d[k].y : 0.0;
}

// cover_rect_samples with L::n samples of a texel per vector operation.
template <typename L>
[[gnu::always_inline]] inline std::size_t cover_samples(const TexelTriangle& tt, std::int32_t t, int x0, int x1, int y0, int y1,
                                                        const double* ox, const double* oy, int count, const KernelRays& rays,
                                                        const SampleSlots& slots, std::size_t first, std::size_t row_stride) {
  using V = typename L::V;
  using M = typename L::M;
  constexpr int kN = L::n;
  std::size_t taken = 0;
  const V zero = {};
  double inv_dy[3];
  inverse_dy(tt, inv_dy);
  const int groups = (count + kN - 1) / kN;  // of L::n samples; the last may be short
  for (int y = y0; y <= y1; ++y) {
    // The row's texels where some sample can be covered: the union of each sample's bounds.
    int xa = x1 + 1, xb = x0 - 1;
    for (int k = 0; k < count; ++k) {
      const double qy = y + oy[k];
      double row_term[3];
      for (int e = 0; e < 3; ++e) row_term[e] = tt.edge_d[e].x * (qy - tt.edge_a[e].y);
      int a, b;
      if (!row_bounds(tt, row_term, inv_dy, ox[k], x0, x1, a, b)) continue;
      xa = std::min(xa, a);
      xb = std::max(xb, b);
    }
    if (xa > xb) continue;
    const std::size_t row = first + std::size_t(y - y0) * row_stride;
    for (int g = 0; g < groups; ++g) {
      // Lanes: samples n g .. n g + n - 1 of each texel (a short group repeats its last sample,
      // masked out).
      M valid;
      V oxv, oyv;
      for (int j = 0; j < kN; ++j) {
        const int k = std::min(kN * g + j, count - 1);
        valid[j] = kN * g + j < count ? -1 : 0;
        oxv[j] = ox[k];
        oyv[j] = oy[k];
      }
      const V qy = (zero + double(y)) + oyv;  // y + oy per lane
      V row_term[3];
      for (int e = 0; e < 3; ++e) row_term[e] = tt.edge_d[e].x * (qy - tt.edge_a[e].y);
      for (int x = xa; x <= xb; ++x) {
        const V qx = (zero + double(x)) + oxv;
        V b[3];
        const unsigned m = covered_lanes(valid, b, tt, row_term, qx, zero);
        if (!m) continue;
        taken += store_lanes<L>(m, b, t, rays, slots, row + std::size_t(x - x0) * std::size_t(count) + std::size_t(kN * g));
      }
    }
  }
  return taken;
}

// Two versions, chosen once at load time by the CPU: AVX2 and the SSE2 baseline.
__attribute__((target_clones("avx2", "default"))) std::size_t cover_samples_by_4(const TexelTriangle& tt, std::int32_t t, int x0,
                                                                                 int x1, int y0, int y1, const double* ox,
                                                                                 const double* oy, int count,
                                                                                 const KernelRays& rays, const SampleSlots& slots,
                                                                                 std::size_t first, std::size_t row_stride) {
  return cover_samples<Lanes4>(tt, t, x0, x1, y0, y1, ox, oy, count, rays, slots, first, row_stride);
}

// AVX-512 (x86-64-v4), eight lanes per instruction.
__attribute__((target("arch=x86-64-v4"))) std::size_t cover_samples_by_8(const TexelTriangle& tt, std::int32_t t, int x0, int x1,
                                                                         int y0, int y1, const double* ox, const double* oy,
                                                                         int count, const KernelRays& rays,
                                                                         const SampleSlots& slots, std::size_t first,
                                                                         std::size_t row_stride) {
  return cover_samples<Lanes8>(tt, t, x0, x1, y0, y1, ox, oy, count, rays, slots, first, row_stride);
}

}  // namespace

// Two versions, chosen once at load time by the CPU: AVX2 and the SSE2 baseline. Neither uses FMA,
// so both give the scalar code's bits.
__attribute__((target_clones("avx2", "default"))) std::size_t cover_rect(const TexelTriangle& tt, std::int32_t t, int x0, int x1,
                                                                         int y0, int y1, double ox, double oy,
                                                                         const KernelRays& rays, const SampleSlots& slots,
                                                                         std::size_t first, std::size_t row_stride) {
  std::size_t taken = 0;
  const V zero = {0.0, 0.0, 0.0, 0.0};
  double inv_dy[3];
  inverse_dy(tt, inv_dy);
  for (int y = y0; y <= y1; ++y) {
    const double qy = y + oy;
    // Edge k's value at q is d.x * (q.y - a.y) - d.y * (q.x - a.x); the first product is the row's.
    double row_term[3];
    for (int k = 0; k < 3; ++k) row_term[k] = tt.edge_d[k].x * (qy - tt.edge_a[k].y);
    const std::size_t row = first + std::size_t(y - y0) * row_stride;
    int xa, xb;
    if (!row_bounds(tt, row_term, inv_dy, ox, x0, x1, xa, xb)) continue;
    for (int x = xa; x <= xb; x += kLanes) {
      const V qx = V{double(x), double(x + 1), double(x + 2), double(x + 3)} + ox;
      const M in = {x <= xb ? -1 : 0, x + 1 <= xb ? -1 : 0, x + 2 <= xb ? -1 : 0, x + 3 <= xb ? -1 : 0};
      V b[3];
      const unsigned m = covered_lanes(in, b, tt, row_term, qx, zero);
      if (!m) continue;
      taken += store_lanes<Lanes4>(m, b, t, rays, slots, row + std::size_t(x - x0));
    }
  }
  return taken;
}

// The widest version the CPU runs whose groups the samples fill (or the one `lanes` asks for): a
// short group takes the lanes one at a time. None uses FMA (-ffp-contract=off for this library:
// x86-64-v4 has it), so all give cover_rect's bits.
std::size_t cover_rect_samples(const TexelTriangle& tt, std::int32_t t, int x0, int x1, int y0, int y1, const double* ox,
                               const double* oy, int count, const KernelRays& rays, const SampleSlots& slots, std::size_t first,
                               std::size_t row_stride, int lanes) {
  if (lanes == 8 || (lanes == 0 && count % 8 == 0 && has_x86_64_v4()))
    return cover_samples_by_8(tt, t, x0, x1, y0, y1, ox, oy, count, rays, slots, first, row_stride);
  return cover_samples_by_4(tt, t, x0, x1, y0, y1, ox, oy, count, rays, slots, first, row_stride);
}

__attribute__((target_clones("avx2", "default"))) std::size_t compact_samples(const SampleSlots& slots, std::size_t slot_count,
                                                                              std::size_t per_texel, bool rays,
                                                                              const CoveredSamples& out) {
  std::size_t n = 0;
  const bool cage = rays && slots.tfar;
  // Entry i (of texel `texel`) to entry n <= i, one value at a time (in place, n may equal i).
  const auto copy_one = [&](std::size_t i, std::size_t texel) {
    out.tri[n] = slots.tri[i];
    for (int c = 0; c < 3; ++c) out.b[c][n] = slots.b[c][i];
    out.texel[n] = std::uint16_t(texel);
    if (rays) {
      for (int c = 0; c < 3; ++c) {
        out.org[c][n] = slots.org[c][i];
        out.dir[c][n] = slots.dir[c][i];
      }
      out.ray_fallback[n] = slots.ray_fallback[i];
      if (cage) {
        out.tfar[n] = slots.tfar[i];
        out.base[n] = slots.base[i];
        out.prefer_lo[n] = slots.prefer_lo[i];
      }
    }
    ++n;
  };
  std::size_t texel = 0, k = 0;  // slot i's texel, and its sample in the texel
  const auto step = [&] {
    if (++k == per_texel) k = 0, ++texel;
  };
  std::size_t i = 0;
  // Four slots at a time; one by one where some are empty.
  for (; i + kLanes <= slot_count; i += kLanes) {
    std::int32_t tri[kLanes];
    std::memcpy(tri, &slots.tri[i], sizeof tri);
    std::uint16_t tex[kLanes];
    for (std::size_t j = 0; j < kLanes; ++j) tex[j] = std::uint16_t(texel), step();
    if ((tri[0] & tri[1] & tri[2] & tri[3]) < 0) continue;  // all empty
    if ((tri[0] | tri[1] | tri[2] | tri[3]) < 0) {          // some empty
      for (std::size_t j = 0; j < kLanes; ++j)
        if (tri[j] >= 0) copy_one(i + j, tex[j]);
      continue;
    }
    std::memcpy(&out.texel[n], tex, sizeof tex);
    // Moved unless in place with no gap yet (then already where they belong); memmove, as in
    // place the four entries from i can overlap the four from n.
    if (out.tri + n != slots.tri + i) {
      std::memcpy(&out.tri[n], tri, sizeof tri);
      for (int c = 0; c < 3; ++c) std::memmove(&out.b[c][n], &slots.b[c][i], kLanes * sizeof(double));
      if (rays) {
        for (int c = 0; c < 3; ++c) {
          std::memmove(&out.org[c][n], &slots.org[c][i], kLanes * sizeof(float));
          std::memmove(&out.dir[c][n], &slots.dir[c][i], kLanes * sizeof(float));
        }
        std::memmove(&out.ray_fallback[n], &slots.ray_fallback[i], kLanes);
        if (cage) {
          std::memmove(&out.tfar[n], &slots.tfar[i], kLanes * sizeof(float));
          std::memmove(&out.base[n], &slots.base[i], kLanes * sizeof(double));
          std::memmove(&out.prefer_lo[n], &slots.prefer_lo[i], kLanes * sizeof(float));
        }
      }
    }
    n += kLanes;
  }
  for (; i < slot_count; ++i, step())
    if (slots.tri[i] >= 0) copy_one(i, texel);
  return n;
}

__attribute__((target_clones("avx2", "default"))) void accumulate_samples(const double* const value[3],
                                                                          const std::uint16_t* texel, std::size_t count,
                                                                          const TexelSums& sums) {
  const auto add_one = [&](std::size_t i) {
    const std::size_t t = texel[i];
    for (int c = 0; c < 3; ++c) sums.sum[c][t] += value[c][i];
    sums.count[t] += 1.0;
  };
  std::size_t i = 0;
  while (i + kLanes <= count) {
    const std::size_t t = texel[i];
    if (texel[i + 1] == t) {
      // A texel's samples one after another (several samples a texel): summed in registers, in
      // order, and stored once.
      double s[3] = {sums.sum[0][t], sums.sum[1][t], sums.sum[2][t]}, n = sums.count[t];
      for (; i < count && texel[i] == t; ++i) {
        for (int c = 0; c < 3; ++c) s[c] += value[c][i];
        n += 1.0;
      }
      for (int c = 0; c < 3; ++c) sums.sum[c][t] = s[c];
      sums.count[t] = n;
      continue;
    }
    // Four samples of four consecutive texels (one sample a texel) are four different texels:
    // their additions are independent, four at a time.
    if (!(texel[i + 1] == t + 1 && texel[i + 2] == t + 2 && texel[i + 3] == t + 3)) {
      for (std::size_t k = 0; k < kLanes; ++k) add_one(i + k);
      i += kLanes;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      V sum, add;
      std::memcpy(&sum, &sums.sum[c][t], sizeof sum);
      std::memcpy(&add, &value[c][i], sizeof add);
      sum += add;
      std::memcpy(&sums.sum[c][t], &sum, sizeof sum);
    }
    V n;
    std::memcpy(&n, &sums.count[t], sizeof n);
    n += 1.0;
    std::memcpy(&sums.count[t], &n, sizeof n);
    i += kLanes;
  }
  for (; i < count; ++i) add_one(i);
}

__attribute__((target_clones("avx2", "default"))) void write_texel_row(const TexelSums& sums, std::size_t first, int width,
                                                                       bool flip_y, double snap, float* rgb,
                                                                       std::uint8_t* covered) {
  const V zero = {0.0, 0.0, 0.0, 0.0};
  for (int x = 0; x < width; x += kLanes) {
    const int n = std::min(kLanes, width - x);
    V3 v;
    V count;
    const std::size_t at = first + std::size_t(x);
    if (n == kLanes) {
      std::memcpy(&v.x, &sums.sum[0][at], sizeof(V));
      std::memcpy(&v.y, &sums.sum[1][at], sizeof(V));
      std::memcpy(&v.z, &sums.sum[2][at], sizeof(V));
      std::memcpy(&count, &sums.count[at], sizeof(V));
    } else {  // a short last block repeats its last texel
      gather(v.x, [&](int k) { return sums.sum[0][at + std::size_t(std::min(k, n - 1))]; });
      gather(v.y, [&](int k) { return sums.sum[1][at + std::size_t(std::min(k, n - 1))]; });
      gather(v.z, [&](int k) { return sums.sum[2][at + std::size_t(std::min(k, n - 1))]; });
      gather(count, [&](int k) { return sums.count[at + std::size_t(std::min(k, n - 1))]; });
    }
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
      V channel;
      codec::to_channel(channel, u);
      out[c] = __builtin_convertvector(channel, F);
    }
    if (filled == 0xfu && n == kLanes) {
      // Four texels, all with samples (most blocks): interleaved to r g b per texel in registers,
      // stored as three vectors.
      const F rg_lo = __builtin_shufflevector(out[0], out[1], 0, 4, 1, 5);     // r0 g0 r1 g1
      const F rg_mid = __builtin_shufflevector(out[0], out[1], 5, 2, 6, 2);    // g1 r2 g2 -
      const F rg_hi = __builtin_shufflevector(out[0], out[1], 3, 7, 3, 7);     // r3 g3 - -
      const F rgb4[3] = {__builtin_shufflevector(rg_lo, out[2], 0, 1, 4, 2),   // r0 g0 b0 r1
                         __builtin_shufflevector(rg_mid, out[2], 0, 5, 1, 2),  // g1 b1 r2 g2
                         __builtin_shufflevector(out[2], rg_hi, 2, 4, 5, 3)};  // b2 r3 g3 b3
      std::memcpy(rgb + 3 * std::size_t(x), rgb4, sizeof rgb4);
      store_lane_flags<kLanes>(covered + x, 0xfu);
      continue;
    }
    for (int k = 0; k < n; ++k) {
      if (!(filled >> k & 1u)) continue;
      for (int c = 0; c < 3; ++c) rgb[3 * std::size_t(x + k) + std::size_t(c)] = out[c][k];
      covered[x + k] = 1;
    }
  }
}

}  // namespace nmbake
