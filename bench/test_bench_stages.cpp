// The bench's compositions of the bake's stages (bench_stages.h) against bake_normal_map: the rays
// it records are those the bake casts, and the trace cast texel by texel casts as many.
#include <gtest/gtest.h>

#include <vector>

#include "bench_stages.h"
#include "raycast.h"
#include "test_support.h"

namespace nmbake::bench {
namespace {

BakeOptions options(int size, int samples) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = samples;
  o.threads = 2;
  return o;
}

TEST(BenchStages, BakeRaysAreTheRaysTheBakeCasts) {
  // The automatic cage, fixed distances, closest, and no hit rule (4 samples: cast in their own
  // order, not texel by texel).
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = test::make_torus(96, 48, 1.0f, 0.37f);
  for (int mode = 0; mode < 4; ++mode) {
    BakeOptions o = options(96, mode >= 2 ? 4 : 1);
    if (mode == 1 || mode == 2) o.front = o.rear = 0.1f;
    if (mode == 2) o.policy = RayPolicy::closest;
    if (mode == 3) o.keep_backfaces = true;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    const BakeRays rays = bake_rays(low, high, o);
    ASSERT_GT(r.stats.trace.rays, 0u);
    EXPECT_EQ(rays.rays.size(), r.stats.trace.rays) << "mode " << mode;
    EXPECT_EQ(rays.stats.distances.front, r.stats.distances.front);
    EXPECT_EQ(rays.stats.distances.rear, r.stats.distances.rear);
    EXPECT_EQ(rays.stats.prepare.centre, r.stats.prepare.centre);
    for (const raycast::Ray& ray : rays.rays) {
      ASSERT_NEAR(glm::length(ray.direction), 1.0f, 1e-5f);
      ASSERT_GT(ray.tfar, ray.tnear);
    }
  }
}

TEST(BenchStages, BakeRaysHitWhereTheBakesHit) {
  // Without the hit rule and with fixed distances each ray's first hit is the sample's: as many
  // hits, at the same mean signed distance (front - t), as the bake counts.
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = test::make_torus(96, 48, 1.0f, 0.37f);
  BakeOptions o = options(128, 4);
  o.keep_backfaces = true;
  o.front = o.rear = 0.025f;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  const BakeRays rays = bake_rays(low, high, o);
  std::vector<glm::vec3> pos;
  for (const glm::vec3& p : high.positions) pos.push_back(glm::vec3(glm::dvec3(p) - rays.stats.prepare.centre));
  const raycast::Scene scene(&pos[0].x, pos.size(), high.position_index.data(), high.triangle_count());
  std::vector<raycast::Hit> hits(rays.rays.size());
  scene.intersect(rays.rays.data(), hits.data(), hits.size());
  std::uint64_t hit_count = 0;
  double sum = 0.0;
  for (const raycast::Hit& h : hits)
    if (h.triangle != raycast::no_hit) ++hit_count, sum += double(o.front) - double(h.t);
  ASSERT_GT(r.stats.trace.misses, 0u);  // the distances leave some samples without a hit
  EXPECT_EQ(hit_count, r.stats.trace.hits);
  EXPECT_NEAR(sum / double(hit_count), r.stats.trace.hit_distance_mean, 1e-9);
}

TEST(BenchStages, TraceByTexelIsTheBakesTrace) {
  // The bake's own trace, with the hit rule and without: as many rays and hits, the same texels.
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = test::make_torus(96, 48, 1.0f, 0.37f);
  for (const bool keep : {false, true}) {
    BakeOptions o = options(96, 4);
    o.keep_backfaces = keep;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    const BakeStats st = trace_by_texel(low, high, o);
    EXPECT_EQ(st.trace.rays, r.stats.trace.rays);
    EXPECT_EQ(st.trace.hits, r.stats.trace.hits);
    EXPECT_EQ(st.trace.texels_covered, r.stats.trace.texels_covered);
    if (!keep) {
      EXPECT_EQ(st.trace.hit_distance_mean, r.stats.trace.hit_distance_mean);
    }
    EXPECT_GT(st.trace.seconds, 0.0);
  }
}

}  // namespace
}  // namespace nmbake::bench
