#include "core/hemisphere.h"

#include "core/lanes.h"

namespace nmbake {

namespace {

using lanes::kLanes;
using lanes::M;
using lanes::V;

// out = m ? a : b per lane (by reference: a 32-byte vector by value changes the calling convention).
[[gnu::always_inline]] inline void select(V& out, const M& m, const V& a, const V& b) { out = m ? a : b; }

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

}  // namespace nmbake
