// Embree against the brute-force reference intersector on fixed-seed random rays.
#include <random>

#include <gtest/gtest.h>

#include "raycast.h"
#include "test_support.h"

using namespace nmbake;

namespace {

void compare_on_random_rays(const Mesh& m, unsigned seed, int count) {
  std::vector<std::uint32_t> idx = m.position_index;
  const float* pos = &m.positions[0].x;
  raycast::Scene scene(pos, m.positions.size(), idx.data(), m.triangle_count());
  raycast::ReferenceIntersector ref(pos, m.positions.size(), idx.data(), m.triangle_count());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> box(-2.0f, 2.0f), dir(-1.0f, 1.0f);
  std::vector<raycast::Ray> rays;
  for (int i = 0; i < count; ++i) {
    glm::vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 1e-3f) d = {0, 0, 1};
    rays.push_back({{box(rng), box(rng), box(rng)}, 0.0f, glm::normalize(d), i % 3 == 0 ? 1.0f : 1e30f});
  }
  std::vector<raycast::Hit> packet(rays.size());
  scene.intersect(rays.data(), packet.data(), rays.size());
  // The same rays as arrays (count not a multiple of 8: the last packet is short).
  raycast::RayArrays arrays(rays.data(), rays.size());
  scene.intersect(arrays.rays(), arrays.hits(), arrays.size());
  const raycast::HitBatch batch = arrays.hits();
  // Filled field by field in place (as the bake fills its rays), the arrays hold the same rays.
  raycast::RayArrays filled(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      filled.origin(c)[i] = rays[i].origin[c];
      filled.direction(c)[i] = rays[i].direction[c];
    }
    filled.tnear()[i] = rays[i].tnear;
    filled.tfar()[i] = rays[i].tfar;
  }
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const raycast::Hit e = scene.intersect(rays[i]);
    const raycast::Hit r = ref.intersect(rays[i]);
    // Packets, arrays and single rays agree exactly.
    EXPECT_EQ(packet[i].triangle, e.triangle) << "ray " << i;
    EXPECT_EQ(packet[i].t, e.t) << "ray " << i;
    ASSERT_EQ(batch.triangle[i], e.triangle) << "ray " << i;
    const raycast::Ray back = arrays.ray(i);  // the arrays give back the ray they were given
    EXPECT_EQ(back.origin, rays[i].origin) << "ray " << i;
    EXPECT_EQ(back.direction, rays[i].direction) << "ray " << i;
    EXPECT_EQ(back.tnear, rays[i].tnear) << "ray " << i;
    EXPECT_EQ(back.tfar, rays[i].tfar) << "ray " << i;
    const raycast::Ray in_place = filled.ray(i);
    EXPECT_EQ(in_place.origin, rays[i].origin) << "ray " << i;
    EXPECT_EQ(in_place.direction, rays[i].direction) << "ray " << i;
    EXPECT_EQ(in_place.tnear, rays[i].tnear) << "ray " << i;
    EXPECT_EQ(in_place.tfar, rays[i].tfar) << "ray " << i;
    EXPECT_EQ(arrays.hit(i).triangle, e.triangle) << "ray " << i;
    if (e.hit()) {
      EXPECT_EQ(batch.t[i], e.t) << "ray " << i;
      EXPECT_EQ(batch.u[i], e.u) << "ray " << i;
      EXPECT_EQ(batch.v[i], e.v) << "ray " << i;
    }
    ASSERT_EQ(e.hit(), r.hit()) << "ray " << i << " embree t " << e.t << " reference t " << r.t;
    if (!e.hit()) continue;
    ++hits;
    EXPECT_NEAR(e.t, r.t, 1e-4f * std::max(1.0f, r.t)) << "ray " << i;
    if (e.triangle == r.triangle) {
      EXPECT_NEAR(e.u, r.u, 1e-4f) << "ray " << i;
      EXPECT_NEAR(e.v, r.v, 1e-4f) << "ray " << i;
    } else {
      // A ray through a shared edge may report either triangle, at the same distance.
      EXPECT_NEAR(e.t, r.t, 1e-5f * std::max(1.0f, r.t)) << "ray " << i;
    }
  }
  EXPECT_GT(hits, count / 10) << "too few hits for the comparison to mean anything";
}

}  // namespace

TEST(Raycast, MatchesReferenceOnTorus) { compare_on_random_rays(test::make_torus(48, 24), 12111, 4003); }

TEST(Raycast, MatchesReferenceOnRandomTriangleSoup) {
  Mesh m;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  for (int t = 0; t < 300; ++t)
    for (int c = 0; c < 3; ++c) {
      m.positions.push_back({u(rng), u(rng), u(rng)});
      m.position_index.push_back(std::uint32_t(m.positions.size() - 1));
    }
  compare_on_random_rays(m, 12112, 4005);
}

TEST(Raycast, RespectsTnearAndTfar) {
  Mesh m = test::make_grid(1, 1);
  raycast::Scene scene(&m.positions[0].x, m.positions.size(), m.position_index.data(), m.triangle_count());
  raycast::Ray r{{0.2f, 0.1f, 1.0f}, 0.0f, {0, 0, -1}, 0.999f};
  EXPECT_FALSE(scene.intersect(r).hit());
  r.tfar = 1.001f;
  const raycast::Hit h = scene.intersect(r);
  ASSERT_TRUE(h.hit());
  EXPECT_NEAR(h.t, 1.0f, 1e-6f);
  r.tnear = 1.0005f;
  EXPECT_FALSE(scene.intersect(r).hit());
}
