// Far-geometry culling (cull.h): the test is conservative, and a bake with it gives the same map as
// one without, bit for bit, while leaving the unreachable triangles out of the BVH.
#include <gtest/gtest.h>

#include <random>

#include "pipeline/bake.h"
#include "core/cull.h"
#include "test_support.h"

using namespace nmbake;

namespace {

// One triangle per row of `corners`: index triples 0..3n-1.
std::vector<std::uint32_t> iota_indices(std::size_t n) {
  std::vector<std::uint32_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = std::uint32_t(i);
  return idx;
}

// `a` with the triangles of `mesh` moved by `offset` appended (positions, normals, UVs).
Mesh joined(const Mesh& a, const Mesh& mesh, const glm::vec3& offset) {
  Mesh m = a;
  const auto np = std::uint32_t(a.positions.size()), nn = std::uint32_t(a.normals.size()), nt = std::uint32_t(a.uvs.size());
  for (const glm::vec3& p : mesh.positions) m.positions.push_back(p + offset);
  m.normals.insert(m.normals.end(), mesh.normals.begin(), mesh.normals.end());
  m.uvs.insert(m.uvs.end(), mesh.uvs.begin(), mesh.uvs.end());
  for (std::uint32_t i : mesh.position_index) m.position_index.push_back(i + np);
  for (std::uint32_t i : mesh.normal_index) m.normal_index.push_back(i + nn);
  for (std::uint32_t i : mesh.uv_index) m.uv_index.push_back(i + nt);
  m.source_face.clear();
  return m;
}

BakeResult bake(const Mesh& low, const Mesh& high, const Mesh* cage, BakeOptions o, bool cull) {
  o.cull_far = cull;
  return bake_normal_map(low, high, cage, o);
}

}  // namespace

TEST(Cull, KeepsExactlyWhatTheMarginReaches) {
  const std::vector<Box> regions = {{glm::dvec3(0.0), glm::dvec3(1.0)}};
  // Triangle 0 inside the box, 1 at 0.5 beyond its +x face, 2 far away.
  const std::vector<glm::vec3> pos = {{0.2f, 0.2f, 0.2f}, {0.8f, 0.2f, 0.2f}, {0.2f, 0.8f, 0.2f},
                                      {1.5f, 0.2f, 0.2f}, {1.6f, 0.2f, 0.2f}, {1.5f, 0.8f, 0.2f},
                                      {50.f, 50.f, 50.f}, {51.f, 50.f, 50.f}, {50.f, 51.f, 50.f}};
  const auto idx = iota_indices(pos.size());
  EXPECT_EQ(triangles_near(regions, 0.6, pos, idx), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(triangles_near(regions, 0.4, pos, idx), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(triangles_near(regions, 100.0, pos, idx), (std::vector<std::uint32_t>{0, 1, 2}));
  const std::vector<std::uint32_t> only_far = {2};
  EXPECT_TRUE(triangles_near(regions, 0.6, pos, idx, &only_far).empty());
  // Listed only below `list_below`: 2 near, listed under a limit of 3, not at 2.
  bool not_listed = true;
  EXPECT_EQ(triangles_near(regions, 0.6, pos, idx, nullptr, 1, 3, &not_listed), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_FALSE(not_listed);
  EXPECT_TRUE(triangles_near(regions, 0.6, pos, idx, nullptr, 2, 2, &not_listed).empty());
  EXPECT_TRUE(not_listed);
}

TEST(Cull, TheAnswerDoesNotDependOnTheThreads) {
  // 300k random small triangles (several chunks of the parallel loop) against a few regions: the
  // same triangles in the same order on 1, 2 and 3 threads, with and without candidates, and the
  // answer is what each triangle's own test gives.
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f), d(-0.05f, 0.05f);
  std::vector<glm::vec3> pos;
  for (int t = 0; t < 300000; ++t) {
    const glm::vec3 c(u(rng), u(rng), u(rng));
    for (int k = 0; k < 3; ++k) pos.push_back(c + glm::vec3(d(rng), d(rng), d(rng)));
  }
  const std::vector<std::uint32_t> idx = iota_indices(pos.size());
  const std::vector<Box> regions = {{glm::dvec3(-1, -1, -1), glm::dvec3(0, 0.5, 0.2)},
                                    {glm::dvec3(2, 2, 2), glm::dvec3(3, 3, 2.5)}};
  const std::vector<std::uint32_t> one = triangles_near(regions, 0.1, pos, idx, nullptr, 1);
  EXPECT_GT(one.size(), 1000u);
  EXPECT_LT(one.size(), 100000u);
  std::vector<std::uint32_t> odd;  // candidates: the odd triangles
  for (std::uint32_t t = 1; t < 300000; t += 2) odd.push_back(t);
  std::vector<std::uint32_t> one_odd;
  for (std::uint32_t t : one)
    if (t % 2) one_odd.push_back(t);
  for (int threads : {2, 3}) {
    EXPECT_EQ(triangles_near(regions, 0.1, pos, idx, nullptr, threads), one) << threads << " threads";
    EXPECT_EQ(triangles_near(regions, 0.1, pos, idx, &odd, threads), one_odd) << threads << " threads";
  }
  for (std::uint32_t t : {one.front(), one.back()})
    EXPECT_EQ(triangles_near(regions, 0.1, pos, {3 * t, 3 * t + 1, 3 * t + 2}).size(), 1u) << t;
}

TEST(Cull, ATriangleTouchingARegionIsKept) {
  // Many small regions along a line; a triangle crossing between two of them, touching one.
  std::vector<Box> regions;
  for (int i = 0; i < 100; ++i) regions.push_back({glm::dvec3(i, 0, 0), glm::dvec3(i + 0.5, 0.5, 0.5)});
  // (Values exact in float and double: the box test compares them exactly.)
  const std::vector<glm::vec3> pos = {{10.5f, 0.625f, 0.125f}, {10.75f, 0.625f, 0.125f}, {10.625f, 0.875f, 0.125f}};
  EXPECT_EQ(triangles_near(regions, 0.125, pos, iota_indices(3)).size(), 1u);
  EXPECT_TRUE(triangles_near(regions, 0.0625, pos, iota_indices(3)).empty());
}

TEST(Cull, FarCopyIsLeftOutAndTheMapIsUnchanged) {
  const Mesh low = test::make_torus(24, 12);
  const Mesh near_high = test::make_torus(96, 48, 1.0f, 0.37f);
  const Mesh high = joined(near_high, near_high, glm::vec3(20.0f, 0.0f, 0.0f));
  BakeOptions o;
  o.width = o.height = 96;
  o.samples = 2;
  o.padding = 4;
  for (const bool given : {true, false}) {
    o.front = o.rear = given ? 0.1f : -1.0f;
    const BakeResult on = bake(low, high, nullptr, o, true), off = bake(low, high, nullptr, o, false);
    EXPECT_EQ(on.stats.select.high_triangles_culled, near_high.triangle_count()) << "given distances: " << given;
    EXPECT_EQ(off.stats.select.high_triangles_culled, 0u);
    EXPECT_EQ(on.stats.distances.front, off.stats.distances.front);
    EXPECT_TRUE(on.map.pixels == off.map.pixels) << "given distances: " << given;
    EXPECT_EQ(on.stats.trace.hits, off.stats.trace.hits);
  }
  // The closest-hit policy reaches outward too: still the same map.
  o.policy = RayPolicy::closest;
  o.front = o.rear = 0.1f;
  EXPECT_TRUE(bake(low, high, nullptr, o, true).map.pixels == bake(low, high, nullptr, o, false).map.pixels);
}

TEST(Cull, GeometryWithinReachStaysIn) {
  // A second layer 0.05 outside the first, inside a front distance of 0.1: nothing culled.
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = joined(test::make_torus(48, 24, 1.0f, 0.37f), test::make_torus(48, 24, 1.0f, 0.40f), glm::vec3(0.0f));
  BakeOptions o;
  o.width = o.height = 64;
  o.front = o.rear = 0.1f;
  const BakeResult on = bake(low, high, nullptr, o, true), off = bake(low, high, nullptr, o, false);
  EXPECT_EQ(on.stats.select.high_triangles_culled, 0u);
  EXPECT_TRUE(on.map.pixels == off.map.pixels);
}

TEST(Cull, CageReachIsRespected) {
  // A cage 0.2 outside the low-poly: rays start on it, so geometry between them must stay in.
  const Mesh low = test::make_torus(24, 12);
  const Mesh cage = test::make_torus(24, 12, 1.0f, 0.55f);
  const Mesh near_high = test::make_torus(96, 48, 1.0f, 0.45f);
  const Mesh high = joined(near_high, near_high, glm::vec3(0.0f, 30.0f, 0.0f));
  BakeOptions o;
  o.width = o.height = 96;
  o.rear = 0.05f;
  const BakeResult on = bake(low, high, &cage, o, true), off = bake(low, high, &cage, o, false);
  EXPECT_EQ(on.stats.select.high_triangles_culled, high.triangle_count() / 2);
  EXPECT_GT(on.stats.trace.hits, on.stats.trace.samples_covered * 9 / 10);
  EXPECT_TRUE(on.map.pixels == off.map.pixels);
}

// Random boxes and triangles, many of them beyond the regions' union on some side or touching its
// faces: every triangle whose box overlaps a grown region is kept, and none whose box lies wholly
// beyond one side of the union (the two answers the grid must give exactly).
TEST(Cull, KeepsEveryOverlapAndNothingBeyondTheUnion) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<float> coord(-4.0f, 4.0f), size(0.0f, 0.6f);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Box> regions(1 + trial * 3);
    for (Box& b : regions) {
      const glm::dvec3 lo(coord(rng) * 0.5f, coord(rng) * 0.5f, coord(rng) * 0.5f);
      b = {lo, lo + glm::dvec3(size(rng), size(rng), size(rng))};
    }
    const double margin = 0.05 * trial;
    std::vector<glm::vec3> positions;
    for (int i = 0; i < 3000; ++i) {
      glm::vec3 p(coord(rng), coord(rng), coord(rng));
      if (i % 7 == 0) p.x = float(regions[0].hi.x + margin);  // on the union's faces and the regions'
      if (i % 11 == 0) p.y = float(regions[0].lo.y - margin);
      positions.push_back(p);
    }
    std::vector<std::uint32_t> index;
    std::uniform_int_distribution<std::uint32_t> pick(0, std::uint32_t(positions.size() - 1));
    for (int t = 0; t < 4000; ++t)
      for (int c = 0; c < 3; ++c) index.push_back(t % 5 == 0 && c > 0 ? index.back() : pick(rng));  // every 5th: one point
    const std::vector<std::uint32_t> kept = triangles_near(regions, margin, positions, index, nullptr, 2);
    std::vector<std::uint8_t> in(index.size() / 3, 0);
    for (std::uint32_t t : kept) in[t] = 1;
    Box all{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (const Box& b : regions) all = {glm::min(all.lo, b.lo - margin), glm::max(all.hi, b.hi + margin)};
    for (std::size_t t = 0; t < in.size(); ++t) {
      glm::dvec3 lo(positions[index[3 * t]]), hi = lo;
      for (int c = 1; c < 3; ++c)
        lo = glm::min(lo, glm::dvec3(positions[index[3 * t + c]])), hi = glm::max(hi, glm::dvec3(positions[index[3 * t + c]]));
      bool overlaps = false;
      for (const Box& b : regions)
        overlaps =
            overlaps || (glm::all(glm::lessThanEqual(lo, b.hi + margin)) && glm::all(glm::greaterThanEqual(hi, b.lo - margin)));
      const bool beyond = glm::any(glm::lessThan(hi, all.lo)) || glm::any(glm::greaterThan(lo, all.hi));
      if (overlaps) {
        EXPECT_TRUE(in[t]) << "trial " << trial << " triangle " << t << " overlaps a region but was left out";
      }
      if (beyond) {
        EXPECT_FALSE(in[t]) << "trial " << trial << " triangle " << t << " lies beyond the union but was kept";
      }
    }
  }
}
