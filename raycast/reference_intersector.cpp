// Brute-force reference intersector for tests: every triangle, double precision, Moeller-Trumbore
// with the nearest hit in (tnear, tfar). Ties in t keep the lower triangle index.
#include <cmath>

#include "raycast.h"

namespace nmbake::raycast {

ReferenceIntersector::ReferenceIntersector(const float* positions, std::size_t vertex_count, const std::uint32_t* indices,
                                           std::size_t triangle_count)
    : positions_(positions), vertex_count_(vertex_count), indices_(indices), triangle_count_(triangle_count) {}

Hit ReferenceIntersector::intersect(const Ray& ray) const {
  const glm::dvec3 o(ray.origin), d(ray.direction);
  Hit best;
  double best_t = ray.tfar;
  auto vertex = [&](std::uint32_t i) { return glm::dvec3(positions_[3 * i], positions_[3 * i + 1], positions_[3 * i + 2]); };
  for (std::size_t t = 0; t < triangle_count_; ++t) {
    const glm::dvec3 p0 = vertex(indices_[3 * t]), p1 = vertex(indices_[3 * t + 1]), p2 = vertex(indices_[3 * t + 2]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
    const glm::dvec3 pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;
    const double inv = 1.0 / det;
    const glm::dvec3 tv = o - p0;
    const double u = glm::dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 qv = glm::cross(tv, e1);
    const double v = glm::dot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double tt = glm::dot(e2, qv) * inv;
    if (tt < ray.tnear || tt > best_t) continue;
    if (tt == best_t && best.hit()) continue;
    best_t = tt;
    best.triangle = std::uint32_t(t);
    best.t = float(tt);
    best.u = float(u);
    best.v = float(v);
  }
  (void)vertex_count_;
  return best;
}

}  // namespace nmbake::raycast
