// UV rasterization: crack-free, no double counting, coverage matches area.
#include <random>

#include <gtest/gtest.h>

#include "core/rasterize.h"
#include "test_support.h"

using namespace nmbake;

TEST(Rasterize, SharedEdgesNeitherCrackNorDoubleCount) {
  // A fan of triangles around a point whose edges pass exactly through texel centres.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  for (int trial = 0; trial < 50; ++trial) {
    Mesh m;
    // The centre stays well inside the heptagon, so the fan does not fold over itself.
    const glm::vec2 c =
        trial % 2 ? glm::vec2(0.5f, 0.5f) : glm::vec2(0.5f + 0.3f * (u(rng) - 0.5f), 0.5f + 0.3f * (u(rng) - 0.5f));
    const int n = 7;
    m.uvs.push_back(c);
    for (int k = 0; k < n; ++k) {
      const float a = 6.2831853f * float(k) / n + (trial % 2 ? 0.0f : 0.3f);
      m.uvs.push_back({0.5f + 0.45f * std::cos(a), 0.5f + 0.45f * std::sin(a)});
    }
    for (int k = 0; k < n; ++k) {
      m.uv_index.insert(m.uv_index.end(), {0u, std::uint32_t(1 + k), std::uint32_t(1 + (k + 1) % n)});
      m.position_index.insert(m.position_index.end(), {0u, 0u, 0u});
    }
    m.positions.push_back({0, 0, 0});
    const int W = 64, H = 64;
    std::vector<int> count(W * H, 0);
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const TexelTriangle tri = setup_texel_triangle(m.corner_uv(t, 0), m.corner_uv(t, 1), m.corner_uv(t, 2), W, H);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          double b[3];
          if (covers(tri, sample_point(x, y, 0.5, 0.5), b)) {
            ++count[y * W + x];
            EXPECT_NEAR(b[0] + b[1] + b[2], 1.0, 1e-12);
            EXPECT_TRUE(x >= tri.xmin && x <= tri.xmax && y >= tri.ymin && y <= tri.ymax) << "outside the bounding box";
          }
        }
    }
    // Every texel centre strictly inside the polygon's hull is covered exactly once.
    std::size_t overlaps = 0;
    const auto owner = rasterize_texel_triangles(m, W, H, &overlaps);
    EXPECT_EQ(overlaps, 0u);
    for (int i = 0; i < W * H; ++i) {
      EXPECT_LE(count[i], 1) << "texel " << i << " counted twice";
      EXPECT_EQ(count[i] == 1, owner[i] >= 0);
    }
    // The centre region (radius 0.3 in UV) lies inside the polygon: no cracks there.
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const glm::vec2 p((float(x) + 0.5f) / float(W), 1.0f - (float(y) + 0.5f) / float(H));
        if (glm::length(p - glm::vec2(0.5f)) < 0.38f) {
          EXPECT_EQ(count[y * W + x], 1) << "crack at " << x << "," << y;
        }
      }
  }
}

TEST(Rasterize, CoverageMatchesUvArea) {
  const Mesh m = test::make_grid(7, 5);  // covers all of [0,1]^2
  for (int size : {1, 3, 16, 100}) {
    std::size_t overlaps = 0;
    const auto owner = rasterize_texel_triangles(m, size, size + 1, &overlaps);
    std::size_t covered = 0;
    for (auto o : owner) covered += o >= 0;
    EXPECT_EQ(covered, std::size_t(size) * (size + 1)) << size;
    EXPECT_EQ(overlaps, 0u);
  }
}

TEST(Rasterize, DegenerateAndFarAwayTrianglesCoverNothing) {
  EXPECT_FALSE(setup_texel_triangle({0.1f, 0.1f}, {0.1f, 0.1f}, {0.1f, 0.1f}, 32, 32).valid());
  EXPECT_FALSE(setup_texel_triangle({0.1f, 0.1f}, {0.2f, 0.2f}, {0.3f, 0.3f}, 32, 32).valid());
  const TexelTriangle far = setup_texel_triangle({1e30f, 1e30f}, {-1e30f, 1e30f}, {1e30f, -1e30f}, 32, 32);
  EXPECT_LE(far.xmax - far.xmin, 31);
  const TexelTriangle outside = setup_texel_triangle({5, 5}, {6, 5}, {5, 6}, 32, 32);
  EXPECT_LT(outside.xmax, outside.xmin);
}
