// Scene::occluded (ambient occlusion's rays) and the first-hit distance of thickness's rays against
// a brute-force double-precision reference on fixed-seed random rays, the group filter, and rays
// through shared edges.
//
// Ties: a ray whose nearest crossing of the interval (tnear, tfar) is decided by rounding (it meets
// a triangle within 1e-5 of the triangle's boundary in barycentrics, or at a t within 1e-5
// (relative) of tnear or tfar) may go either way in float; the reference marks those rays and the
// comparison skips them, after checking they are few. Every other ray must agree exactly.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "core/hemisphere.h"
#include "raycast.h"

using namespace nmbake;

namespace {

struct Soup {
  std::vector<float> positions;  // xyz per vertex
  std::vector<std::uint32_t> indices;
  std::size_t triangles() const { return indices.size() / 3; }
  glm::dvec3 vertex(std::uint32_t i) const { return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]}; }
};

// A closed torus around z (radii R, r), u x v quads split in two, wound outwards.
Soup torus(int nu, int nv, float big_r = 1.0f, float small_r = 0.35f) {
  Soup s;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float a = 6.2831853f * float(i) / float(nu), b = 6.2831853f * float(j) / float(nv);
      s.positions.insert(s.positions.end(), {(big_r + small_r * std::cos(b)) * std::cos(a),
                                             (big_r + small_r * std::cos(b)) * std::sin(a), small_r * std::sin(b)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      s.indices.insert(s.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
  return s;
}

// Random triangles in [-1, 1]^3, some of them slivers.
Soup random_soup(int count, std::uint64_t seed) {
  Soup s;
  SampleStream r(seed);
  for (int t = 0; t < count; ++t) {
    const glm::dvec3 c(2 * r.next() - 1, 2 * r.next() - 1, 2 * r.next() - 1);
    for (int k = 0; k < 3; ++k) {
      const double size = t % 7 == 0 ? 0.01 : 0.3;
      for (int a = 0; a < 3; ++a) s.positions.push_back(float(c[a] + size * (r.next() - 0.5)));
      s.indices.push_back(std::uint32_t(3 * t + k));
    }
  }
  return s;
}

// The plane z = height as an n x n grid over [0, 1]^2, two triangles a cell.
void add_grid(Soup& s, int n, float height) {
  const auto first = std::uint32_t(s.positions.size() / 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) s.positions.insert(s.positions.end(), {float(i) / float(n), float(j) / float(n), height});
  auto id = [&](int i, int j) { return first + std::uint32_t(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      s.indices.insert(s.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
}

// What the reference makes of a ray: occluded for certain, free for certain, or a tie (rounding
// could decide); and the first crossing's distance (any facing) when it is not a tie.
struct Verdict {
  enum { clear, blocked, tie } occlusion;
  bool first_is_tie;
  double first_t;  // infinity when none
};

Verdict reference(const Soup& s, const raycast::Ray& ray, const std::uint32_t* triangle_group, std::uint32_t group) {
  constexpr double eps_bary = 1e-5, eps_t = 1e-5;
  const glm::dvec3 o(ray.origin), d(ray.direction);
  const double tnear = ray.tnear, tfar = ray.tfar;
  auto slack = [&](double t) { return eps_t * std::max(1.0, std::fabs(t)); };
  bool sure = false, maybe = false;
  double first = std::numeric_limits<double>::infinity(), second = first;  // nearest sure crossings
  double nearest_maybe = first;
  for (std::size_t t = 0; t < s.triangles(); ++t) {
    if (triangle_group && triangle_group[t] != group) continue;
    const glm::dvec3 p0 = s.vertex(s.indices[3 * t]), p1 = s.vertex(s.indices[3 * t + 1]), p2 = s.vertex(s.indices[3 * t + 2]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    // A ray in the triangle's plane: only a grazing touch (a tie) can happen.
    if (std::fabs(det) <= 1e-12 * glm::length(e1) * glm::length(e2) * glm::length(d)) {
      const double dist = std::fabs(glm::dot(o - p0, glm::normalize(glm::cross(e1, e2))));
      if (glm::length(glm::cross(e1, e2)) > 0.0 && dist < 1e-6) maybe = true;
      continue;
    }
    const glm::dvec3 tv = o - p0, qv = glm::cross(tv, e1);
    const double u = glm::dot(tv, pv) / det, v = glm::dot(d, qv) / det, tt = glm::dot(e2, qv) / det;
    const double margin = std::min({u, v, 1.0 - u - v});
    if (margin < -eps_bary || tt < tnear - slack(tt) || tt > tfar + slack(tt)) continue;  // clearly missed
    if (margin > eps_bary && tt > tnear + slack(tt) && tt < tfar - slack(tt)) {
      sure = true;
      if (tt < first) second = first, first = tt;
      else second = std::min(second, tt);
    } else {
      maybe = true;
      nearest_maybe = std::min(nearest_maybe, tt);
    }
  }
  Verdict v;
  v.occlusion = sure ? Verdict::blocked : maybe ? Verdict::tie : Verdict::clear;
  v.first_t = first;
  // The first crossing is unsure when a doubtful one lies before (or at) it; two sure ones at one
  // distance (a ray through an edge) give the same t either way.
  v.first_is_tie = std::isfinite(nearest_maybe) && nearest_maybe <= first + slack(first);
  (void)second;
  return v;
}

// Fixed-seed rays: origins in a box, directions any length, a mix of intervals.
std::vector<raycast::Ray> random_rays(int count, std::uint64_t seed, float box) {
  std::vector<raycast::Ray> rays;
  SampleStream r(seed);
  const float inf = std::numeric_limits<float>::infinity();
  for (int i = 0; i < count; ++i) {
    raycast::Ray ray;
    ray.origin = glm::vec3(float(box * (2 * r.next() - 1)), float(box * (2 * r.next() - 1)), float(box * (2 * r.next() - 1)));
    glm::vec3 d(float(2 * r.next() - 1), float(2 * r.next() - 1), float(2 * r.next() - 1));
    if (glm::length(d) < 1e-3f) d = glm::vec3(0, 0, 1);
    ray.direction = d * float(0.5 + r.next());  // not unit: t in units of |direction|
    ray.tnear = i % 5 == 0 ? 0.2f : 0.0f;
    ray.tfar = i % 3 == 0 ? 0.4f : i % 3 == 1 ? 1.5f : inf;
    rays.push_back(ray);
  }
  return rays;
}

// AO's rays on the torus: from points just off the surface, cosine-weighted about its normal.
std::vector<raycast::Ray> ao_rays(int points, int per_point, float distance, bool inverted) {
  std::vector<raycast::Ray> rays;
  const double big_r = 1.0, small_r = 0.35;
  for (int p = 0; p < points; ++p) {
    SampleStream s(sample_key(std::uint64_t(p), 0, 3));
    const double a = 6.283185307179586 * s.next(), b = 6.283185307179586 * s.next();
    const glm::dvec3 ring(std::cos(a), std::sin(a), 0.0);
    const glm::dvec3 n = std::cos(b) * ring + glm::dvec3(0, 0, std::sin(b));
    const glm::dvec3 at = big_r * ring + (small_r + (inverted ? -2e-3 : 2e-3)) * n;
    for (int k = 0; k < per_point; ++k) {
      SampleStream d(sample_key(std::uint64_t(p), std::uint64_t(k), 4));
      const glm::dvec2 u = d.next2();
      rays.push_back({glm::vec3(at), 0.0f, glm::vec3(cosine_direction(inverted ? -n : n, u.x, u.y)), distance});
    }
  }
  return rays;
}

std::vector<std::uint8_t> occluded(const raycast::Scene& scene, const std::vector<raycast::Ray>& rays,
                                   const raycast::SecondaryRayOptions& options = {}, const std::uint32_t* ray_group = nullptr) {
  raycast::RayArrays arrays(rays.data(), rays.size());
  raycast::RayBatch batch = arrays.rays();
  batch.group = ray_group;
  std::vector<std::uint8_t> out(rays.size(), 7);
  scene.occluded(batch, out.data(), rays.size(), options);
  return out;
}

// Every ray against the reference: exact agreement off ties, few ties, and enough of both answers.
void expect_matches_reference(const Soup& s, const std::vector<raycast::Ray>& rays, int min_percent_occluded = 10,
                              const std::uint32_t* triangle_group = nullptr, const std::vector<std::uint32_t>& ray_group = {}) {
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  raycast::SecondaryRayOptions options;
  options.group = triangle_group;
  const std::vector<std::uint8_t> got = occluded(scene, rays, options, ray_group.empty() ? nullptr : ray_group.data());
  // The project's brute-force ReferenceIntersector (nearest hit in [tnear, tfar], one group) agrees
  // with the verdicts off ties too.
  const raycast::ReferenceIntersector project_reference(s.positions.data(), s.positions.size() / 3, s.indices.data(),
                                                        s.triangles());
  int ties = 0, hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_LE(got[i], 1) << "ray " << i;
    const Verdict v = reference(s, rays[i], triangle_group, ray_group.empty() ? 0u : ray_group[i]);
    if (v.occlusion == Verdict::tie) {
      ++ties;
      continue;
    }
    EXPECT_EQ(got[i], v.occlusion == Verdict::blocked ? 1 : 0) << "ray " << i;
    if (!triangle_group) {
      EXPECT_EQ(got[i], project_reference.intersect(rays[i]).hit() ? 1 : 0) << "ray " << i;
    }
    hits += got[i];
  }
  EXPECT_LE(ties, int(rays.size()) / 200) << "too many ties for the comparison to mean much";
  EXPECT_GT(hits, int(rays.size()) * min_percent_occluded / 100);
  EXPECT_LT(hits, int(rays.size()) * 9 / 10);
}

}  // namespace

TEST(RaycastOcclusion, MatchesReferenceOnRandomRaysAtTorus) {
  const Soup s = torus(48, 24);
  expect_matches_reference(s, random_rays(3001, 12111, 1.6f));
}

TEST(RaycastOcclusion, MatchesReferenceOnRandomTriangleSoup) {
  const Soup s = random_soup(400, 4);
  expect_matches_reference(s, random_rays(2500, 909, 1.2f));
}

TEST(RaycastOcclusion, MatchesReferenceOnAmbientOcclusionRays) {
  // Rays as AO makes them (64 per point, tfar = the AO distance, long enough to cross the hole), as
  // many in one call as a bake's tile (several of Embree's blocks, the last one short).
  const Soup s = torus(64, 32);
  const std::vector<raycast::Ray> rays = ao_rays(40, 64, 2.5f, false);
  expect_matches_reference(s, rays, 5);  // a torus hides little of its own sky (about 6%)
}

TEST(RaycastOcclusion, AgreesWithIntersectAndWithOneRayAtATime) {
  const Soup s = torus(32, 16);
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  const std::vector<raycast::Ray> rays = random_rays(2051, 31, 1.6f);
  const std::vector<std::uint8_t> all = occluded(scene, rays);
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const raycast::Hit h = scene.intersect(rays[i]);
    const std::vector<std::uint8_t> one = occluded(scene, {rays[i]});
    EXPECT_EQ(one[0], all[i]) << "ray " << i;
    // A hit strictly inside the interval means occluded; no hit means free (ties at the ends aside).
    if (h.hit() && h.t > rays[i].tnear * 1.0001f + 1e-6f && h.t < rays[i].tfar * 0.9999f) {
      EXPECT_EQ(all[i], 1) << "ray " << i;
    }
    if (!h.hit()) {
      EXPECT_EQ(all[i], 0) << "ray " << i;
    }
    hits += all[i];
  }
  EXPECT_GT(hits, 200);
}

TEST(RaycastOcclusion, RaysThroughSharedEdgesAndVerticesHitInThePrimaryBvh) {
  // A 16 x 16 grid (z = 0): rays straight down through every vertex and the middle of every edge
  // (diagonals too: a cell's centre is on one), and slanted ones through the same points. The
  // primary rays' robust BVH lets none slip between two triangles (its test is watertight). The
  // secondary rays' fast BVH may let such rays go (raycast.h: rays of measure zero), but not most
  // of them, and never one through a triangle's interior (the same directions through a point off
  // every edge of each cell).
  Soup s;
  const int n = 16;
  add_grid(s, n, 0.0f);
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  const glm::vec3 dirs[] = {glm::vec3(0, 0, -1), glm::vec3(0.3f, -0.2f, -1), glm::vec3(-1, -1, -0.5f)};
  std::vector<raycast::Ray> on_edges, inside;
  for (int i = 1; i < 2 * n; ++i)
    for (int j = 1; j < 2 * n; ++j) {
      const glm::vec3 target(float(i) / float(2 * n), float(j) / float(2 * n), 0.0f);
      for (const glm::vec3 d : dirs) on_edges.push_back({target - 0.5f * d, 0.0f, d, 1.0f});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (const glm::vec2 f : {glm::vec2(0.3f, 0.6f), glm::vec2(0.7f, 0.2f)}) {
        const glm::vec3 target((float(i) + f.x) / float(n), (float(j) + f.y) / float(n), 0.0f);
        for (const glm::vec3 d : dirs) inside.push_back({target - 0.5f * d, 0.0f, d, 1.0f});
      }
  std::vector<raycast::Hit> hits(on_edges.size());
  scene.intersect(on_edges.data(), hits.data(), on_edges.size());
  for (std::size_t i = 0; i < on_edges.size(); ++i) EXPECT_TRUE(hits[i].hit()) << "ray " << i;
  const std::vector<std::uint8_t> edge_occluded = occluded(scene, on_edges);
  std::size_t caught = 0;
  for (std::uint8_t o : edge_occluded) caught += o;
  EXPECT_GT(caught, on_edges.size() * 3 / 4);
  const std::vector<std::uint8_t> inside_occluded = occluded(scene, inside);
  for (std::size_t i = 0; i < inside.size(); ++i) EXPECT_EQ(inside_occluded[i], 1) << "ray " << i;
}

TEST(RaycastOcclusion, EmptyIntervalsAndNoRays) {
  const Soup s = torus(16, 8);
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  const float inf = std::numeric_limits<float>::infinity();
  // Along x from (-2, 0.05, 0.03) the ray is inside the tube for t in about (0.66, 1.35) (x from
  // -1.34 to -0.65; off the mesh's vertices): tnear past tfar, tfar = -inf, intervals short of the
  // tube or inside it are free.
  const glm::vec3 o(-2, 0.05f, 0.03f), d(1, 0, 0);
  const std::vector<raycast::Ray> rays = {{o, 1.0f, d, 0.5f}, {o, 0.0f, d, -inf}, {o, 0.0f, d, 0.6f},
                                          {o, 0.0f, d, 0.7f}, {o, 0.7f, d, 1.3f}, {o, 0.7f, d, inf}};
  const std::vector<std::uint8_t> got = occluded(scene, rays);
  EXPECT_EQ(got, (std::vector<std::uint8_t>{0, 0, 0, 1, 0, 1}));
  scene.occluded(raycast::RayArrays(rays.data(), rays.size()).rays(), nullptr, 0);  // no rays: nothing read or written
}

TEST(RaycastOcclusion, GroupsSeeOnlyTheirOwnTriangles) {
  // Planes z = 1 (group 0) and z = 2 (group 1), rays up from z = 0: each ray sees only its group's plane.
  Soup s;
  add_grid(s, 4, 1.0f);
  add_grid(s, 4, 2.0f);
  std::vector<std::uint32_t> tri_group(s.triangles(), 0);
  std::fill(tri_group.begin() + long(s.triangles() / 2), tri_group.end(), 1u);
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  std::vector<raycast::Ray> rays;
  std::vector<std::uint32_t> ray_group;
  for (int i = 0; i < 20; ++i)
    for (float tfar : {1.5f, 2.5f})
      for (std::uint32_t g : {0u, 1u, 2u}) {
        rays.push_back({{0.13f + 0.037f * float(i), 0.41f, 0.0f}, 0.0f, {0.0f, 0.0f, 1.0f}, tfar});
        ray_group.push_back(g);
      }
  raycast::SecondaryRayOptions options;
  options.group = tri_group.data();
  const std::vector<std::uint8_t> got = occluded(scene, rays, options, ray_group.data());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool expect = ray_group[i] == 0 || (ray_group[i] == 1 && rays[i].tfar > 2.0f);  // group 2 has no triangles
    EXPECT_EQ(got[i], expect ? 1 : 0) << "ray " << i << " group " << ray_group[i] << " tfar " << rays[i].tfar;
  }
  // Groups given for the triangles but none for the rays: every ray is in group 0.
  const std::vector<std::uint8_t> group0 = occluded(scene, rays, options);
  for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(group0[i], 1) << "ray " << i;
  // No groups: every triangle is there for every ray.
  const std::vector<std::uint8_t> all = occluded(scene, rays, {}, ray_group.data());
  for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(all[i], 1) << "ray " << i;
}

TEST(RaycastOcclusion, GroupsMatchReferenceOnRandomRays) {
  // The soup in 3 groups, random rays in 3 groups: the reference sees only the ray's group.
  const Soup s = random_soup(1500, 8);
  std::vector<std::uint32_t> tri_group(s.triangles());
  for (std::size_t t = 0; t < tri_group.size(); ++t) tri_group[t] = std::uint32_t(mix64(t) % 3);
  const std::vector<raycast::Ray> rays = random_rays(2400, 77, 1.2f);
  std::vector<std::uint32_t> ray_group(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) ray_group[i] = std::uint32_t(i % 3);
  expect_matches_reference(s, rays, 10, tri_group.data(), ray_group);
}

TEST(RaycastThickness, FirstHitDistanceOfAnyFacingMatchesReference) {  // intersect under a rule, and first_hits
  // Thickness's rays: from just under the torus's surface along the inverted normal, the first
  // crossing's distance whatever its facing (the far wall's inside is a back face), tfar = D.
  // Scene::intersect gives it under HitRule{.skip_backfaces = false} (and no rule at all without
  // groups); with groups, only the ray's group counts.
  const Soup s = torus(64, 32);
  raycast::Scene scene(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.triangles());
  std::vector<raycast::Ray> rays = ao_rays(24, 32, 0.5f, true);
  const std::vector<raycast::Ray> more = random_rays(1000, 5, 1.6f);
  rays.insert(rays.end(), more.begin(), more.end());
  std::vector<std::uint32_t> tri_group(s.triangles()), ray_group(rays.size());
  for (std::size_t t = 0; t < tri_group.size(); ++t) tri_group[t] = (t / 64) % 2 ? 1u : 0u;  // rings of the torus
  for (std::size_t i = 0; i < rays.size(); ++i) ray_group[i] = std::uint32_t(mix64(i) % 2);
  for (bool grouped : {false, true}) {
    SCOPED_TRACE(grouped ? "groups" : "one group");
    raycast::HitRule rule;
    rule.skip_backfaces = false;
    rule.group = grouped ? tri_group.data() : nullptr;
    raycast::RayArrays arrays(rays.data(), rays.size());
    raycast::RayBatch batch = arrays.rays();
    batch.group = grouped ? ray_group.data() : nullptr;
    scene.intersect(batch, arrays.hits(), rays.size(), &rule);
    // The same through first_hits, in the secondary rays' BVH.
    raycast::RayArrays fast(rays.data(), rays.size());
    raycast::RayBatch fast_batch = fast.rays();
    fast_batch.group = batch.group;
    raycast::SecondaryRayOptions options;
    options.group = rule.group;
    scene.first_hits(fast_batch, fast.hits(), rays.size(), options);
    raycast::RayArrays plain(rays.data(), rays.size());
    if (!grouped) scene.intersect(plain.rays(), plain.hits(), rays.size());  // no rule: the same hits
    int ties = 0, hits = 0, back = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const raycast::Hit h = arrays.hit(i);
      if (!grouped) {
        EXPECT_EQ(plain.hit(i).hit() ? plain.hit(i).t : -1.0f, h.hit() ? h.t : -1.0f) << "ray " << i;
      }
      const Verdict v = reference(s, rays[i], grouped ? tri_group.data() : nullptr, ray_group[i]);
      if (v.first_is_tie) {
        ++ties;
        continue;
      }
      ASSERT_EQ(h.hit(), std::isfinite(v.first_t)) << "ray " << i << " reference t " << v.first_t;
      const raycast::Hit f = fast.hit(i);
      ASSERT_EQ(f.hit(), std::isfinite(v.first_t)) << "first_hits, ray " << i << " reference t " << v.first_t;
      if (f.hit()) {
        EXPECT_NEAR(f.t, v.first_t, 1e-5 * std::max(1.0, v.first_t)) << "first_hits, ray " << i;
      }
      if (!h.hit()) continue;
      ++hits;
      EXPECT_NEAR(h.t, v.first_t, 1e-5 * std::max(1.0, v.first_t)) << "ray " << i;
      // A back face: the triangle's winding normal (outwards) along the ray.
      const std::uint32_t* c = &s.indices[3 * std::size_t(h.triangle)];
      const glm::dvec3 p0 = s.vertex(c[0]), p1 = s.vertex(c[1]), p2 = s.vertex(c[2]);
      back += glm::dot(glm::cross(p1 - p0, p2 - p0), glm::dvec3(rays[i].direction)) > 0.0;
    }
    EXPECT_LE(ties, int(rays.size()) / 100);
    EXPECT_GT(hits, int(rays.size()) / 10);
    EXPECT_GT(back, 80) << "the inverted-normal rays should meet back faces";
  }
}
