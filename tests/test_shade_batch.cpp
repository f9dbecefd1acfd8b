// encode_hits_per_pixel (four or eight samples per vector instruction) gives exactly the bits of its
// one-at-a-time definition, interpolate_frame + the interpolated hit normal + encode_tangent_normal,
// and flags the degenerate hit normals it leaves to the bake's one-at-a-time path.
#include <cstring>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "test_support.h"
#include "trace/shade_batch.h"
#include "core/tangent_frames.h"

using namespace nmbake;

namespace {

using nmbake::test::same_bits;

LowTriangle random_shading_triangle(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  LowTriangle lt;
  for (int c = 0; c < 3; ++c) {
    const glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), 1.0f));
    const glm::vec3 t = glm::normalize(glm::cross(n, glm::vec3(0.3f, 1.0f, 0.2f)));
    lt.p[c] = glm::dvec3(u(rng), u(rng), u(rng));
    lt.ray_n[c] = glm::dvec3(n);
    lt.n[c] = glm::dvec3(n);
    lt.t[c] = glm::dvec4(glm::dvec3(t), u(rng) < 0.0f ? -1.0 : 1.0);  // mirrored corners too
  }
  return lt;
}

}  // namespace

TEST(ShadeBatch, BitIdenticalToOneAtATime) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_real_distribution<float> uf(-1.0f, 1.0f);
  std::vector<LowTriangle> low;
  for (int i = 0; i < 6; ++i) low.push_back(random_shading_triangle(rng));
  std::vector<glm::vec3> high_normals;
  for (int i = 0; i < 3 * 50; ++i) high_normals.push_back(glm::normalize(glm::vec3(uf(rng), uf(rng), 1.0f)));
  for (int c = 0; c < 3; ++c) {
    high_normals[3 * 7 + c] = glm::vec3(0.0f);  // a zero hit normal: flagged
    high_normals[3 * 9 + c] *= 1e-13f;          // squared length below 1e-24: flagged
    high_normals[3 * 11 + c] *= 1e-10f;         // short but above it: encoded at its own length
  }
  const std::size_t n = 77;  // not a multiple of the lane count
  // The first 30 samples share a triangle (the kernel broadcasts it), the rest mix triangles.
  // Every version this CPU runs: 4 lanes, and 8 on an AVX-512 one.
  for (const int lanes : {4, 8}) {
    if (!kernel_lanes_available(lanes)) {
      EXPECT_EQ(lanes, 8);
      continue;
    }
    SCOPED_TRACE(std::to_string(lanes) + " lanes");
    std::vector<std::int32_t> low_tri(n);
    std::vector<double> b[3] = {std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
    std::vector<std::uint32_t> high_tri(n);
    std::vector<float> hu(n), hv(n);
    for (std::size_t i = 0; i < n; ++i) {
      b[0][i] = u(rng), b[1][i] = (1.0 - b[0][i]) * u(rng), b[2][i] = 1.0 - b[0][i] - b[1][i];
      low_tri[i] = std::int32_t(i < 30 ? 1 : i % low.size());
      high_tri[i] = i % 17 == 5 ? 0xffffffffu : std::uint32_t((i * 13) % 50);  // some misses: flagged
      hu[i] = float(u(rng)), hv[i] = float((1.0 - double(hu[i])) * u(rng));
    }
    const ShadeSamples samples{low_tri.data(), {b[0].data(), b[1].data(), b[2].data()}, high_tri.data(), hu.data(), hv.data()};
    std::vector<double> value[3] = {std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
    double* const value_c[3] = {value[0].data(), value[1].data(), value[2].data()};
    std::vector<std::uint8_t> degenerate(n, 7);
    encode_hits_per_pixel(low.data(), high_normals.data(), samples, n, value_c, degenerate.data(), lanes);
    std::size_t checked = 0, misses = 0, short_normals = 0, scaled = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (high_tri[i] == 7 || high_tri[i] == 9 || high_tri[i] == 0xffffffffu) {
        EXPECT_EQ(degenerate[i], 1) << i;
        misses += high_tri[i] == 0xffffffffu;
        short_normals += high_tri[i] == 9;
        continue;
      }
      ASSERT_EQ(degenerate[i], 0) << i;
      const LowTriangle& lt = low[std::size_t(low_tri[i])];
      const double bi[3] = {b[0][i], b[1][i], b[2][i]};
      const PixelFrame frame = interpolate_frame(lt.n, lt.t, bi);
      const double w[3] = {1.0 - double(hu[i]) - double(hv[i]), double(hu[i]), double(hv[i])};
      glm::dvec3 nh(0.0);
      for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(high_normals[3 * high_tri[i] + c]);
      const glm::dvec3 expect = encode_tangent_normal(frame, nh);
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(value[c][i], expect[c])) << "sample " << i << " axis " << c;
      ++checked;
      scaled += high_tri[i] == 11;
    }
    EXPECT_GT(checked, 55u);
    EXPECT_GT(short_normals, 0u);
    EXPECT_GT(scaled, 0u);
    EXPECT_GT(misses, 3u);
  }
}
