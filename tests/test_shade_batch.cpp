// encode_hits_per_pixel (four samples per vector instruction) gives exactly the bits of its
// one-at-a-time definition, interpolate_frame + the normalized hit normal + encode_tangent_normal,
// and flags the degenerate hit normals it leaves to the bake's one-at-a-time path.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "shade_batch.h"
#include "tangent_frames.h"

using namespace nmbake;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

LowTriangle random_low_triangle(std::mt19937& rng) {
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
  for (int i = 0; i < 6; ++i) low.push_back(random_low_triangle(rng));
  std::vector<glm::vec3> high_normals;
  for (int i = 0; i < 3 * 50; ++i) high_normals.push_back(glm::normalize(glm::vec3(uf(rng), uf(rng), 1.0f)));
  for (int c = 0; c < 3; ++c) high_normals[3 * 7 + c] = glm::vec3(0.0f);  // a zero hit normal: flagged
  const std::size_t n = 77;  // not a multiple of the lane count
  std::vector<HitSample> samples(n);
  for (std::size_t i = 0; i < n; ++i) {
    HitSample& s = samples[i];
    s.b[0] = u(rng), s.b[1] = (1.0 - s.b[0]) * u(rng), s.b[2] = 1.0 - s.b[0] - s.b[1];
    s.low_tri = std::uint32_t(i < 30 ? 1 : i % low.size());
    s.high_tri = std::uint32_t((i * 13) % 50);
    s.u = float(u(rng)), s.v = float((1.0 - double(s.u)) * u(rng));
  }
  std::vector<glm::dvec3> value(n);
  std::vector<std::uint8_t> degenerate(n);
  encode_hits_per_pixel(low.data(), high_normals.data(), samples.data(), n, value.data(), degenerate.data());
  std::size_t checked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const HitSample& s = samples[i];
    if (s.high_tri == 7) {
      EXPECT_TRUE(degenerate[i]) << i;
      continue;
    }
    ASSERT_FALSE(degenerate[i]) << i;
    const LowTriangle& lt = low[s.low_tri];
    const PixelFrame frame = interpolate_frame(lt.n, lt.t, s.b);
    const double w[3] = {1.0 - double(s.u) - double(s.v), double(s.u), double(s.v)};
    glm::dvec3 nh(0.0);
    for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(high_normals[3 * s.high_tri + c]);
    const glm::dvec3 expect = encode_tangent_normal(frame, nh / glm::length(nh));
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(value[i][c], expect[c])) << "sample " << i << " axis " << c;
    ++checked;
  }
  EXPECT_GT(checked, 60u);
}
