// Known answers for bake_normal_map on analytic scenes (style.md: pbrt-style analytic scenes with
// explicit tolerances), plus properties every bake must have.
#include <cmath>

#include <gtest/gtest.h>

#include "bake.h"
#include "rasterize.h"
#include "test_support.h"

using namespace nmbake;
using test::angle_deg;
using test::decode_rgb;

namespace {

constexpr double kPi = 3.14159265358979323846;

BakeOptions options(int size, int samples = 1) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = samples;
  o.padding = 0;
  return o;
}

long quantize(float c, int bits) { return std::lround(double(c) * ((1 << bits) - 1)); }

}  // namespace

TEST(Bake, MeshBakedOntoItselfIsExactlyFlat) {
  const Mesh m = test::make_torus(64, 32);
  for (int samples : {1, 4}) {
    BakeOptions o = options(256, samples);
    o.front = o.rear = 0.05f;
    const BakeResult r = bake_normal_map(m, m, nullptr, o);
    EXPECT_EQ(r.stats.misses, 0u);
    EXPECT_GT(r.stats.texels_covered, 256u * 256u * 9 / 10);
    for (std::size_t i = 0; i < r.coverage.size(); ++i) {
      if (!r.coverage[i]) continue;
      const float* c = &r.map.pixels[3 * i];
      ASSERT_EQ(quantize(c[0], 8), 128) << "texel " << i << " samples " << samples;
      ASSERT_EQ(quantize(c[1], 8), 128) << "texel " << i << " samples " << samples;
      ASSERT_EQ(quantize(c[2], 8), 255) << "texel " << i << " samples " << samples;
      ASSERT_EQ(quantize(c[0], 16), 32768) << "texel " << i;
      ASSERT_EQ(quantize(c[1], 16), 32768) << "texel " << i;
    }
  }
}

TEST(Bake, QuadAgainstTiltedPlaneGivesThePlaneNormal) {
  const Mesh low = test::make_grid(1, 1);
  Mesh high = test::make_grid(3, 3, -1.5f, 1.5f, -1.5f, 1.5f);
  for (glm::vec3& p : high.positions) p.z = 0.2f * p.x + 0.1f * p.y + 0.05f;
  high.normals = {glm::vec3(glm::normalize(glm::dvec3(-0.2, -0.1, 1.0)))};
  BakeOptions o = options(64);
  o.front = o.rear = 1.0f;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  const glm::dvec3 expect = glm::normalize(glm::dvec3(-0.2, -0.1, 1.0));
  ASSERT_EQ(r.stats.texels_covered, 64u * 64u);
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    const float* c = &r.map.pixels[3 * i];
    ASSERT_LT(angle_deg(decode_rgb(c), expect), 1e-4) << "texel " << i;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(quantize(c[k], 8), std::lround((expect[k] * 0.5 + 0.5) * 255.0)) << "texel " << i;
  }
  // DirectX convention: the same map with green flipped.
  o.green_down = true;
  const BakeResult d = bake_normal_map(low, high, nullptr, o);
  for (std::size_t i = 0; i < d.coverage.size(); ++i) {
    EXPECT_EQ(d.map.pixels[3 * i], r.map.pixels[3 * i]);
    EXPECT_FLOAT_EQ(d.map.pixels[3 * i + 1], 1.0f - r.map.pixels[3 * i + 1]);
  }
}

TEST(Bake, HeightFieldMatchesAnalyticNormal) {
  // z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2, 513 x 513 vertices with analytic normals.
  auto h = [](double x, double y) { return 0.05 * std::sin(2 * kPi * x) * std::sin(3 * kPi * y); };
  auto n = [](double x, double y) {
    const double hx = 0.05 * 2 * kPi * std::cos(2 * kPi * x) * std::sin(3 * kPi * y);
    const double hy = 0.05 * 3 * kPi * std::sin(2 * kPi * x) * std::cos(3 * kPi * y);
    return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
  };
  const Mesh high = test::make_height_field(512, 512, h, n);
  const Mesh low = test::make_grid(1, 1);
  BakeOptions o = options(512);
  o.front = o.rear = 0.06f;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  ASSERT_EQ(r.stats.misses, 0u);
  double sum = 0.0, worst = 0.0;
  std::size_t count = 0;
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 512; ++x) {
      const float* c = r.map.at(x, y);
      float q[3];
      for (int k = 0; k < 3; ++k) q[k] = float(double(quantize(c[k], 16)) / 65535.0);  // 16-bit output
      const double u = (x + 0.5) / 512, v = 1.0 - (y + 0.5) / 512;
      const double e = angle_deg(decode_rgb(q), n(-1 + 2 * u, -1 + 2 * v));
      sum += e;
      worst = std::max(worst, e);
      ++count;
    }
  const double mean = sum / double(count);
  RecordProperty("mean_deg", std::to_string(mean));
  RecordProperty("max_deg", std::to_string(worst));
  std::printf("height field 512^2 16-bit: mean %.5f deg, max %.5f deg\n", mean, worst);
  EXPECT_LE(mean, 0.005);
  EXPECT_LE(worst, 0.05);
}

TEST(Bake, ResultsDoNotDependOnThreadCount) {
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = test::make_torus(96, 48, 1.0f, 0.37f);
  BakeOptions o = options(128, 4);
  o.front = o.rear = 0.1f;
  o.padding = 4;
  o.threads = 1;
  const BakeResult a = bake_normal_map(low, high, nullptr, o);
  o.threads = 2;
  const BakeResult b = bake_normal_map(low, high, nullptr, o);
  ASSERT_EQ(a.map.pixels.size(), b.map.pixels.size());
  EXPECT_TRUE(a.map.pixels == b.map.pixels);
  EXPECT_TRUE(a.coverage == b.coverage);
}

TEST(Bake, MissesAreCountedFlatAndMasked) {
  const Mesh low = test::make_grid(2, 2);
  // The high-poly covers only x < 0.
  Mesh high = test::make_grid(1, 1, -1.2f, 0.0f, -1.2f, 1.2f);
  for (glm::vec3& p : high.positions) p.z = 0.01f;
  BakeOptions o = options(32);
  o.front = o.rear = 0.1f;
  o.miss_mask = true;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  EXPECT_GT(r.stats.misses, 0u);
  EXPECT_GT(r.stats.hits, 0u);
  EXPECT_EQ(r.stats.hits + r.stats.misses, r.stats.samples_covered);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const float* c = r.map.at(x, y);
      EXPECT_EQ(quantize(c[0], 8), 128);
      EXPECT_EQ(quantize(c[2], 8), 255);
      EXPECT_EQ(r.miss_mask.pixels[std::size_t(y) * 32 + x], x < 16 ? 0.0f : 1.0f) << x << "," << y;
    }
}

TEST(Bake, AbsurdOptionsAreRefused) {
  const Mesh m = test::make_grid(1, 1);
  BakeOptions o = options(0);
  EXPECT_THROW(bake_normal_map(m, m, nullptr, o), UsageError);
  o = options(100000);
  EXPECT_THROW(bake_normal_map(m, m, nullptr, o), ResourceError);
  o = options(16, 0);
  EXPECT_THROW(bake_normal_map(m, m, nullptr, o), UsageError);
  Mesh no_uv = m;
  no_uv.uv_index.clear();
  EXPECT_THROW(bake_normal_map(no_uv, m, nullptr, options(16)), InputError);
}

TEST(Bake, AutoDistancesCoverTheOffset) {
  const Mesh low = test::make_grid(4, 4);
  Mesh high = test::make_grid(8, 8, -1.5f, 1.5f, -1.5f, 1.5f);
  for (glm::vec3& p : high.positions) p.z = 0.03f;
  BakeOptions o = options(32);
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  EXPECT_TRUE(r.stats.auto_distances);
  EXPECT_GE(r.stats.front, 0.03f);
  EXPECT_LT(r.stats.front, 0.1f);
  EXPECT_EQ(r.stats.misses, 0u);
  EXPECT_NEAR(r.stats.hit_distance_mean, 0.03, 1e-5);
}
