// The bake's rays and the shading of one sample, for the trace stage (trace.h): the definitions
// its vector kernels (trace/) give the bits of, and the cases they leave to one at a time.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include <glm/glm.hpp>

#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"
#include "raycast.h"

namespace nmbake {

inline glm::dvec3 low_point(const LowTriangle& lt, const double b[3]) {
  codec::Vec3<double> p;
  corner_sum(p, lt.p, b);
  return from_codec(p);
}

// The ray normal at b (low_point_and_normal, shade_batch.h); where opposite corner normals cancel,
// the face normal.
inline glm::dvec3 low_ray_normal(const LowTriangle& lt, const double b[3]) {
  codec::Vec3<double> p, n;
  double len2;
  low_point_and_normal(p, n, len2, lt, b);
  if (len2 > 1e-24) return from_codec(n);
  const glm::dvec3 f = glm::cross(lt.p[1] - lt.p[0], lt.p[2] - lt.p[0]);
  const double fl = glm::length(f);
  return fl > 0.0 ? f / fl : glm::dvec3(0, 0, 1);
}

// A sample's ray with a cage: P, the unit direction from the cage point to P, the distance from
// the cage point to P, how far out the ray searches (at least that), and the rear distance.
struct CageRay {
  glm::dvec3 p, d;
  double len, search, rear;
};

inline CageRay cage_ray(const LowTriangle& lt, const CageTriangle& ct, const double b[3], double diagonal) {
  CageRay r;
  r.p = low_point(lt, b);
  const glm::dvec3 pc = b[0] * ct.corner[0] + b[1] * ct.corner[1] + b[2] * ct.corner[2];
  r.rear = b[0] * ct.rear[0] + b[1] * ct.rear[1] + b[2] * ct.rear[2];
  const double search = b[0] * ct.search[0] + b[1] * ct.search[1] + b[2] * ct.search[2];
  const glm::dvec3 d = r.p - pc;
  r.len = glm::length(d);
  if (r.len > 1e-9 * diagonal) {
    r.d = d / r.len;
  } else {  // a cage point on the low-poly gives no direction: the ray normal's
    r.d = -low_ray_normal(lt, b);
    r.len = 0.0;
  }
  // Where a neighbouring part limits the cage, rays search on beyond it, as far out as the
  // high-poly was found there, for a hit to take only when none lies within the cage.
  r.search = std::max(r.len, search);
  return r;
}

// The inward ray of a cage sample: from `search` out along the line through the cage point to the
// rear distance beyond P; the part before the cage point is looked at last (prefer_lo).
inline raycast::Ray inward_ray(const CageRay& c, double* signed_base, float* prefer_lo) {
  signed_base[0] = c.search;
  prefer_lo[0] = c.search > c.len ? float(c.search - c.len) : 0.0f;
  return {glm::vec3(c.p - c.search * c.d), 0.0f, glm::vec3(c.d), float(c.search + c.rear)};
}

// How a bake casts its rays (BakeOptions::policy, with the distances chosen).
struct RaySetup {
  float front = 0.0f, rear = 0.0f;
  bool cage = false, closest = false;
  double diagonal = 1.0;
};

// The rays of the sample at barycentrics b of low-poly triangle `tri` (two for the closest-hit
// policy, else one) and, per ray, the distance from P to its origin along it and the part of the
// ray where hits are looked for first (raycast::RayBatch::prefer_lo/hi). Returns the count.
inline int sample_rays(const Prepared& s, std::size_t tri, const double b[3], const RaySetup& r, raycast::Ray* rays,
                       double* signed_base, float* prefer_lo, float* prefer_hi) {
  prefer_lo[0] = prefer_lo[1] = 0.0f;
  prefer_hi[0] = prefer_hi[1] = std::numeric_limits<float>::infinity();
  const LowTriangle& lt = s.low_tris[tri];
  if (r.cage) {
    const CageRay c = cage_ray(lt, s.cage_tris[tri], b, r.diagonal);
    if (r.closest) {  // from P out to the cage point (and on, searching), and in to the rear distance
      signed_base[0] = signed_base[1] = 0.0;
      rays[0] = {glm::vec3(c.p), 0.0f, glm::vec3(-c.d), float(c.search)};
      rays[1] = {glm::vec3(c.p), 0.0f, glm::vec3(c.d), float(c.rear)};
      if (c.search > c.len) prefer_hi[0] = float(c.len);
      return 2;
    }
    rays[0] = inward_ray(c, signed_base, prefer_lo);
    return 1;
  }
  const glm::dvec3 p = low_point(lt, b), n = low_ray_normal(lt, b);  // the default ray: default_ray (shade_batch.h)
  if (r.closest) {
    signed_base[0] = signed_base[1] = 0.0;
    rays[0] = {glm::vec3(p), 0.0f, glm::vec3(n), r.front};
    rays[1] = {glm::vec3(p), 0.0f, glm::vec3(-n), r.rear};
    return 2;
  }
  signed_base[0] = r.front;
  codec::Vec3<double> org, dir;
  default_ray(org, dir, to_codec(p), to_codec(n), double(r.front));
  rays[0] = {glm::vec3(from_codec(org)), 0.0f, glm::vec3(from_codec(dir)), r.front + r.rear};
  return 1;
}

// Of a sample's rays' hits (its rays start at `first`), the index of the one that counts, and its
// signed distance from the low-poly (positive: outside).
inline std::size_t chosen_hit(const raycast::HitBatch& hits, std::size_t first, const double* signed_base, bool closest,
                              double* dist) {
  if (closest) {
    const std::size_t out = first, in = first + 1;
    const bool out_hit = hits.triangle[out] != raycast::no_hit, in_hit = hits.triangle[in] != raycast::no_hit;
    // A hit taken only for want of another on its ray (outside the cage, then one whose normal
    // points away) yields to a better one on the other ray.
    const auto rank = [&](std::size_t i) {
      const int f = hits.flags ? hits.flags[i] : 0;
      return (f & raycast::hit_normal_disagrees) ? 2 : (f & raycast::hit_outside_preferred) ? 1 : 0;
    };
    const bool prefer_out = out_hit && in_hit && rank(out) != rank(in) ? rank(out) < rank(in) : hits.t[out] <= hits.t[in];
    if (out_hit && (!in_hit || prefer_out)) {
      *dist = hits.t[out];
      return out;
    }
    *dist = -double(hits.t[in]);
    return in;
  }
  *dist = signed_base[first] - hits.t[first];
  return first;
}

// One sample's value, one at a time: every case, with the fallbacks for degenerate hit normals and
// frames. encode_hits_per_pixel (shade_batch.h) gives the same bits for the common case, many at a
// time. `h` indexes the BVH's triangles (s.bvh_index, s.bvh_normals).
glm::dvec3 shade_sample(const Prepared& s, const HighScene& scene, std::size_t tri, const double b[3], const raycast::Hit& h,
                        const BakeOptions& opt);

}  // namespace nmbake
