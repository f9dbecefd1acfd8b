#include "ray_batch.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace nmbake {
namespace {

// Four doubles, one per sample; plain IEEE operations lane by lane, no FMA (as shade_batch.cpp).
typedef double V __attribute__((vector_size(32)));
typedef float F __attribute__((vector_size(16)));
constexpr int kLanes = 4;

// A triangle's corner values, the same in every lane (samples of one triangle) or one per lane.
struct Corners {
  V p[3][3], rn[3][3];  // [corner][axis]
};

[[gnu::always_inline]] inline void load(Corners& c, const LowTriangle* const lp[kLanes]) {
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) {
      c.p[k][a] = V{lp[0]->p[k][a], lp[1]->p[k][a], lp[2]->p[k][a], lp[3]->p[k][a]};
      c.rn[k][a] = V{lp[0]->ray_n[k][a], lp[1]->ray_n[k][a], lp[2]->ray_n[k][a], lp[3]->ray_n[k][a]};
    }
}
[[gnu::always_inline]] inline void load(Corners& c, const LowTriangle& lt) {
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) {
      const double pa = lt.p[k][a], na = lt.ray_n[k][a];  // broadcast (not 0 + x, which turns -0 into +0)
      c.p[k][a] = V{pa, pa, pa, pa};
      c.rn[k][a] = V{na, na, na, na};
    }
}
[[gnu::always_inline]] inline void store(float* to, const V& v, std::size_t n) {
  const F f = __builtin_convertvector(v, F);  // round to nearest, as glm::vec3(dvec3)
  if (n == kLanes)
    std::memcpy(to, &f, sizeof f);
  else
    for (std::size_t k = 0; k < n; ++k) to[k] = f[k];
}

}  // namespace

// Two versions, chosen once at load time by the CPU: AVX2 and the baseline (SSE2).
__attribute__((target_clones("avx2", "default"))) void surface_rays(const LowTriangle* low, const SampleArrays& s,
                                                                     std::size_t count, float front, float rear,
                                                                     const RayArrays& rays, std::uint8_t* fallback) {
  const float tfar = front + rear;
  const double f = double(front);
  for (std::size_t i = 0; i < count; i += kLanes) {
    const std::size_t n = std::min<std::size_t>(kLanes, count - i);
    std::size_t idx[kLanes];
    for (int k = 0; k < kLanes; ++k) idx[k] = i + std::min<std::size_t>(std::size_t(k), n - 1);  // a short block repeats its last sample
    V b[3];
    b[0] = V{s.b0[idx[0]], s.b0[idx[1]], s.b0[idx[2]], s.b0[idx[3]]};
    b[1] = V{s.b1[idx[0]], s.b1[idx[1]], s.b1[idx[2]], s.b1[idx[3]]};
    b[2] = V{s.b2[idx[0]], s.b2[idx[1]], s.b2[idx[2]], s.b2[idx[3]]};
    Corners c;
    const std::uint32_t t0 = s.tri[idx[0]];
    if (s.tri[idx[1]] == t0 && s.tri[idx[2]] == t0 && s.tri[idx[3]] == t0) {
      load(c, low[t0]);  // the common case: four samples of one triangle
    } else {
      const LowTriangle* lp[kLanes] = {&low[t0], &low[s.tri[idx[1]]], &low[s.tri[idx[2]]], &low[s.tri[idx[3]]]};
      load(c, lp);
    }
    // low_point and low_ray_normal: ((b0 * c0) + (b1 * c1)) + (b2 * c2) per axis, as glm sums them.
    V p[3], nr[3];
    for (int a = 0; a < 3; ++a) {
      p[a] = b[0] * c.p[0][a] + b[1] * c.p[1][a] + b[2] * c.p[2][a];
      nr[a] = b[0] * c.rn[0][a] + b[1] * c.rn[1][a] + b[2] * c.rn[2][a];
    }
    const V len2 = nr[0] * nr[0] + nr[1] * nr[1] + nr[2] * nr[2];
    V len;
    for (int k = 0; k < kLanes; ++k) len[k] = std::sqrt(len2[k]);
    for (int a = 0; a < 3; ++a) nr[a] = nr[a] / len;
    // sample_rays, cage-first without a cage: origin P + front * N, direction -N.
    store(rays.org_x + i, p[0] + f * nr[0], n);
    store(rays.org_y + i, p[1] + f * nr[1], n);
    store(rays.org_z + i, p[2] + f * nr[2], n);
    store(rays.dir_x + i, -nr[0], n);
    store(rays.dir_y + i, -nr[1], n);
    store(rays.dir_z + i, -nr[2], n);
    for (std::size_t k = 0; k < n; ++k) {
      rays.tnear[i + k] = 0.0f;
      rays.tfar[i + k] = tfar;
      fallback[i + k] = !(len2[k] > 1e-24);
    }
  }
}

}  // namespace nmbake
